// The co-simulation rig's step contract (runner/cosim_rig.h, DESIGN.md "Loop timing per 1 ms step"),
// on a toy device: a single integrator x' = tau as the plant, a node that sends the index of its
// sampling instant, a driver that holds the latest command, and a controller that answers each
// sample with the index of its tick.
#include "runner/cosim_rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "protocol/messages.h"

namespace exotwin {
namespace {

constexpr double kDt = 1e-3;
constexpr uint16_t kIdSample = msg::kIdJointStatusHip, kIdCommand = msg::kIdJointCommandHip;

CanFrame IndexFrame(uint16_t id, int32_t index) {
  CanFrame f;
  f.id = id;
  f.dlc = 4;
  std::memcpy(f.data.data(), &index, 4);
  return f;
}

int32_t IndexOf(const CanFrame& f) {
  int32_t v;
  std::memcpy(&v, f.data.data(), 4);
  return v;
}

// What the toy device saw at each call, in call order.
struct Trace {
  std::vector<std::string> calls;
  std::vector<double> held;          // per step: the torque the plant held over it
  std::vector<double> log_t, log_x;  // per log instant: t and the plant state the callback saw
  std::vector<double> state_t;       // per log instant: the time of the plant's state
};

class ToyDevice : public CosimDevice {
 public:
  ToyDevice(CosimRig& rig, Trace* trace)
      : node_(rig.bus().AddNode("toy_node", {kIdCommand})), trace_(trace) {}

  void BeginStep(double t) override { Note("begin", t); }
  double StepPlant(double t) override {
    Note("plant", t);
    trace_->held.push_back(tau_);
    x_ += kDt * tau_;
    clock_ += kDt;
    return clock_;
  }
  void SampleStepStart(double t) override { Note("start", t); }
  void LatchDrivers(double t, double dt) override {
    Note("latch", t);
    CanFrame f;
    while (node_->Receive(&f) == CanStatus::kOk) tau_ = IndexOf(f);
  }
  void SampleNodes(double t) override {
    Note("nodes", t);
    node_->Send(IndexFrame(kIdSample, static_cast<int32_t>(std::lround(t / kDt))));
    state_time_ = clock_;
  }
  void EndStep(double t) override { Note("end", t); }
  void LogSample(double t) override {
    Note("log", t);
    trace_->log_t.push_back(t);
    trace_->log_x.push_back(x_);
    trace_->state_t.push_back(state_time_);
  }

  double clock() const { return clock_; }

 private:
  void Note(const char* what, double t) {
    if (trace_->calls.size() < 40) trace_->calls.push_back(std::string(what) + "@" + std::to_string(std::lround(t / (0.5 * kDt))));
  }
  CanBus* node_;
  Trace* trace_;
  double x_ = 0, clock_ = 0, state_time_ = 0;
  double tau_ = -1;  // no command yet
};

// The controller: at each tick, the index of the newest sample it received, and the EMG frames so far.
struct ToyController {
  explicit ToyController(CanBus* endpoint) : ep(endpoint) {}
  CanBus* ep;
  int32_t ticks = 0;
  std::vector<int32_t> seen_sample;
  std::vector<int> emg_frames_at_tick;
  int emg_frames = 0;
  void Tick(double t) {
    CanFrame f;
    int32_t newest = -1;
    while (ep->Receive(&f) == CanStatus::kOk) {
      if (f.id == kIdSample) newest = IndexOf(f);
      if (f.id == msg::kIdEmgSamples) ++emg_frames;
    }
    seen_sample.push_back(newest);
    emg_frames_at_tick.push_back(emg_frames);
    ep->Send(IndexFrame(kIdCommand, ticks++));
  }
};

hwsim::VirtualCanBusConfig FastBus() {
  hwsim::VirtualCanBusConfig c;
  c.latency = 50e-6;
  c.jitter = 10e-6;
  return c;
}

CosimSchedule Schedule(long steps, int steps_per_tick, long log_every, CosimClock clock = CosimClock::kGrid) {
  CosimSchedule s;
  s.dt = kDt;
  s.steps = steps;
  s.steps_per_tick = steps_per_tick;
  s.log_every = log_every;
  s.clock = clock;
  return s;
}

// The toy device and controller on one rig.
struct ToyRig {
  CosimRig rig{FastBus(), nullptr, 0.0};
  ToyController ctrl{rig.bus().AddNode("controller", {kIdSample, msg::kIdEmgSamples})};
  Trace trace;
  ToyDevice dev{rig, &trace};
  double Run(long steps, int steps_per_tick, long log_every, CosimClock clock = CosimClock::kGrid) {
    return rig.Run(Schedule(steps, steps_per_tick, log_every, clock), dev, [this](double t) { ctrl.Tick(t); });
  }
};

TEST(CosimRig, OneStepRunsInTheDocumentedOrder) {
  ToyRig toy;
  toy.Run(2, 1, 1);
  // Times in half steps: the tick is not a device call; the nodes sample t = 0 before the first step.
  const std::vector<std::string> expected = {"nodes@0", "begin@0", "plant@0", "start@0", "latch@2", "nodes@2",
                                             "end@2",   "log@2",   "begin@2", "plant@2", "start@2", "latch@4",
                                             "nodes@4", "end@4",   "log@4"};
  EXPECT_EQ(toy.trace.calls, expected);
}

TEST(CosimRig, TickSeesTheSampleOfItsStepStartAndItsCommandActsOneStepLater) {
  ToyRig toy;
  const long n = 50;
  toy.Run(n, 1, 1);
  ASSERT_EQ(toy.ctrl.seen_sample.size(), static_cast<size_t>(n));
  ASSERT_EQ(toy.trace.held.size(), static_cast<size_t>(n));
  EXPECT_EQ(toy.trace.held[0], -1) << "no command before the first tick";
  for (long k = 0; k < n; ++k) EXPECT_EQ(toy.ctrl.seen_sample[k], k) << "the tick at (k + 1/2) dt works on the frame sampled at k dt";
  for (long k = 1; k < n; ++k) EXPECT_EQ(toy.trace.held[k], k - 1) << "the tick of step k - 1 drives step k";
}

TEST(CosimRig, SlowerControllerTicksEveryNthStep) {
  ToyRig toy;
  const long n = 20;
  toy.Run(n, 2, 1);
  ASSERT_EQ(toy.ctrl.seen_sample.size(), static_cast<size_t>(n / 2));
  for (long i = 0; i < n / 2; ++i) EXPECT_EQ(toy.ctrl.seen_sample[i], 2 * i);
  for (long k = 1; k < n; ++k) EXPECT_EQ(toy.trace.held[k], (k - 1) / 2) << k;
}

TEST(CosimRig, SampleCallbackSeesThePlantStateOfItsInstant) {
  for (CosimClock clock : {CosimClock::kGrid, CosimClock::kPlant}) {
    ToyRig toy;
    const long n = 30, every = 4;
    const double t_end = toy.Run(n, 1, every, clock);
    ASSERT_EQ(toy.trace.log_t.size(), static_cast<size_t>((n + every - 1) / every));
    double x = 0;
    for (long k = 0, i = 0; k < n; ++k) {
      x += kDt * toy.trace.held[k];
      if (k % every) continue;
      if (clock == CosimClock::kGrid) {
        EXPECT_EQ(toy.trace.log_t[i], (k + 1) * kDt);
        EXPECT_NEAR(toy.trace.state_t[i], toy.trace.log_t[i], 1e-12);  // the plant's clock: rounding only
      } else {
        EXPECT_EQ(toy.trace.state_t[i], toy.trace.log_t[i]);
      }
      EXPECT_DOUBLE_EQ(toy.trace.log_x[i], x) << "the state at the end of step " << k;
      ++i;
    }
    EXPECT_EQ(t_end, clock == CosimClock::kPlant ? toy.dev.clock() : n * kDt);
  }
}

TEST(CosimRig, EmgNodeSendsOneFrameAtEachStepEndBeforeTheNextTick) {
  ToyRig toy;
  CanBus* emg_ep = toy.rig.bus().AddNode("emg_amplifier", {0x7FF});
  MuscleModel muscles(DrawMuscleParams(1), kDt);
  SyntheticEmg electrodes(DefaultSyntheticEmgConfig(), 3);
  toy.rig.AttachEmg(emg_ep, &muscles, &electrodes);
  const long n = 25;
  toy.Run(n, 1, 1);
  ASSERT_NE(toy.rig.emg_node(), nullptr);
  EXPECT_EQ(toy.rig.emg_node()->frames_sent(), static_cast<uint32_t>(n));
  for (long k = 0; k < n; ++k) EXPECT_EQ(toy.ctrl.emg_frames_at_tick[k], k) << "EMG sampled at dt .. k dt";
}

// Begin + Advance in parts of any size (the Python twin's controller periods) runs the steps Run runs.
TEST(CosimRig, RunInPartsIsTheRun) {
  ToyRig whole;
  const long n = 37;
  const double t_end = whole.Run(n, 2, 3);
  ToyRig parts;
  parts.rig.Begin(Schedule(n, 2, 3), parts.dev);
  EXPECT_FALSE(parts.rig.finished());
  const auto tick = [&parts](double t) { parts.ctrl.Tick(t); };
  long ran = 0;
  for (long size : {1L, 2L, 5L, 0L, 3L}) {
    EXPECT_EQ(parts.rig.Advance(size, tick), size);
    ran += size;
    EXPECT_EQ(parts.rig.steps_run(), ran);
    EXPECT_EQ(parts.rig.time(), ran * kDt);
  }
  EXPECT_EQ(parts.rig.Advance(std::numeric_limits<long>::max(), tick), n - ran);
  EXPECT_TRUE(parts.rig.finished());
  EXPECT_EQ(parts.rig.Advance(5, tick), 0) << "nothing after the schedule's end";
  EXPECT_EQ(parts.rig.time(), t_end);
  EXPECT_EQ(parts.trace.calls, whole.trace.calls);
  EXPECT_EQ(parts.trace.held, whole.trace.held);
  EXPECT_EQ(parts.trace.log_t, whole.trace.log_t);
  EXPECT_EQ(parts.trace.log_x, whole.trace.log_x);
  EXPECT_EQ(parts.ctrl.seen_sample, whole.ctrl.seen_sample);
}

TEST(CosimRig, ScheduleOfAScenario) {
  Scenario s;
  s.source = "toy.yaml";
  s.protocol.duration = 2.5;
  s.controller.rate_hz = 500;
  s.log_rate_hz = 100;
  const CosimSchedule c = ScheduleOf(s, kDt);
  EXPECT_EQ(c.steps, 2500);
  EXPECT_EQ(c.steps_per_tick, 2);
  EXPECT_EQ(c.log_every, 10);
  EXPECT_EQ(c.clock, CosimClock::kGrid);
  s.controller.rate_hz = 300;
  try {
    ScheduleOf(s, kDt);
    FAIL() << "300 Hz is not 1000 Hz / n";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "toy.yaml: controller.rate_hz: expected the physics rate (1000 Hz) divided by an integer");
  }
}

}  // namespace
}  // namespace exotwin
