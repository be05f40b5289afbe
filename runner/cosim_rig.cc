// The lockstep co-simulation rig: see cosim_rig.h.
#include "runner/cosim_rig.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"
#include "core/stop_signal.h"

namespace exotwin {
namespace {

constexpr long kProgressEvery = 2000;  // steps between progress reports

}  // namespace

CosimSchedule ScheduleOf(const Scenario& s, double dt, CosimClock clock) {
  const double ctrl_dt = 1.0 / s.controller.rate_hz;
  if (std::abs(ctrl_dt / dt - std::round(ctrl_dt / dt)) > 1e-9 || ctrl_dt < dt - 1e-12)
    throw InputError(s.source + ": controller.rate_hz: expected the physics rate (1000 Hz) divided by an integer");
  CosimSchedule c;
  c.dt = dt;
  c.steps = std::lround(s.protocol.duration / dt);
  c.steps_per_tick = static_cast<int>(std::lround(ctrl_dt / dt));
  c.log_every = std::max(1L, std::lround(1.0 / (s.log_rate_hz * dt)));
  c.clock = clock;
  return c;
}

double TrialEpoch(const Scenario& s, int trial) { return trial * (s.protocol.duration + 1.0); }

hwsim::VirtualCanBusConfig BusConfigOf(const HardwareSpec& hw, uint64_t seed) {
  hwsim::VirtualCanBusConfig c;
  c.bitrate = hw.can_bitrate;
  c.latency = hw.can_latency;
  c.jitter = hw.can_jitter;
  c.drop_probability = hw.can_drop_rate;
  c.seed = seed;
  return c;
}

TrialLog::TrialLog(const std::string& path, const std::vector<std::string>& columns,
                   const std::vector<std::string>& comments, CapturedLog* capture, std::unique_ptr<BagLog> bag)
    : csv_(path, columns, comments), capture_(capture), bag_(std::move(bag)) {}

void TrialLog::Row(const double* values, size_t n, const double* velocity) {
  csv_.Row(values, n);
  if (bag_) bag_->Row(values, n, velocity);
  if (!capture_) return;
  const size_t columns = capture_->columns.size();
  capture_->values.insert(capture_->values.end(), values, values + std::min(n, columns));
  if (n < columns) capture_->values.insert(capture_->values.end(), columns - n, 0.0);
}

TrialLogs OpenTrialLogs(const std::string& dir, int trial, int trials, const std::vector<std::string>& measured_columns,
                        const std::vector<std::string>& truth_columns, const std::vector<std::string>& comments,
                        std::vector<std::string>* files, LogCapture* capture, size_t rows, RunBag* bag,
                        double epoch) {
  const std::string suffix = trials > 1 ? "_trial" + std::to_string(trial + 1) : "";
  const std::string measured = "measured" + suffix + ".csv", truth = "truth" + suffix + ".csv";
  CapturedLog* captured[2] = {nullptr, nullptr};
  if (capture) {
    captured[0] = &capture->emplace_back(CapturedLog{measured, measured_columns, {}});
    captured[1] = &capture->emplace_back(CapturedLog{truth, truth_columns, {}});
    for (CapturedLog* c : captured) c->values.reserve(rows * c->columns.size());
  }
  TrialLogs logs;
  logs.measured = std::make_unique<TrialLog>(dir + "/" + measured, measured_columns, comments, captured[0],
                                             bag ? bag->Open(BagLogKind::kMeasured, measured_columns, epoch) : nullptr);
  logs.truth = std::make_unique<TrialLog>(dir + "/" + truth, truth_columns, comments, captured[1],
                                          bag ? bag->Open(BagLogKind::kTruth, truth_columns, epoch) : nullptr);
  files->push_back(measured);
  files->push_back(truth);
  return logs;
}

CosimRig::CosimRig(const hwsim::VirtualCanBusConfig& bus, CandumpWriter* log, double epoch) : bus_(bus) {
  if (!log) return;
  bus_.SetTap([log, epoch](const CanFrame& f) {
    CanFrame g = f;
    g.t += epoch;
    log->Write(g);
  });
}

void CosimRig::AttachEmg(CanBus* endpoint, const MuscleModel* muscles, SyntheticEmg* electrodes) {
  emg_node_ = std::make_unique<hwsim::EmgNode>(hwsim::EmgAmplifierSpec{}, endpoint);
  muscles_ = muscles;
  electrodes_ = electrodes;
}

double CosimRig::Run(const CosimSchedule& sc, CosimDevice& device, const std::function<void(double)>& tick,
                     const CosimProgress& progress) {
  Begin(sc, device);
  Advance(sc.steps, tick, progress);
  return t_;
}

void CosimRig::Begin(const CosimSchedule& sc, CosimDevice& device) {
  schedule_ = sc;
  device_ = &device;
  t_ = 0.0;
  stopped_by_ = 0;
  steps_run_ = 0;
  device.SampleNodes(t_);
}

long CosimRig::Advance(long steps, const std::function<void(double)>& tick, const CosimProgress& progress) {
  const CosimSchedule& sc = schedule_;
  CosimDevice& device = *device_;
  const double dt = sc.dt;
  double t = t_;
  const long first = steps_run_;
  const long end = steps >= sc.steps - first ? sc.steps : first + std::max(0L, steps);  // no overflow for LONG_MAX
  for (long k = first; k < end && stopped_by_ == 0; ++k) {
    device.BeginStep(t);
    const double plant_clock = device.StepPlant(t);
    device.SampleStepStart(t);
    if (k % sc.steps_per_tick == 0) {
      bus_.AdvanceTo(t + 0.5 * dt);
      tick(t + 0.5 * dt);
    }
    bus_.AdvanceTo(t + 0.999 * dt);
    device.LatchDrivers(t + dt, dt);
    t = sc.clock == CosimClock::kGrid ? static_cast<double>(k + 1) * dt : plant_clock;
    t_ = t;
    device.SampleNodes(t);
    if (emg_node_) {  // the amplifier samples the electrodes at 1 kHz and sends one frame
      const MuscleVec v = electrodes_->Sample(muscles_->electrical_activation());
      std::array<double, hwsim::EmgAmplifier::kChannels> in{};
      for (int c = 0; c < kNumMuscles; ++c) in[c] = v[c];
      emg_node_->Sample(t, in);
    }
    device.EndStep(t);
    if (k % sc.log_every == 0) device.LogSample(t);
    if (progress.bar && k % kProgressEvery == 0) progress.bar->Update(progress.done + static_cast<size_t>(k));
    steps_run_ = k + 1;
    if (const int sig = StopSignal(); sig != 0 && k + 1 < sc.steps) stopped_by_ = sig;  // step 8
  }
  return steps_run_ - first;
}

}  // namespace exotwin
