// The lockstep co-simulation rig of the device runners (runner/exowheel_runner.cc, runner/hal_runner.cc):
// one virtual CAN bus, the device's plant and nodes (a CosimDevice), the EMG amplifier node of the
// human and the real controller's tick, advanced in physics steps of dt (1 ms). Run() is the one
// implementation of DESIGN.md "Loop timing per 1 ms step". Step k covers [t, t + dt]:
//   1. device.BeginStep(t): switches acting from t (fault injection);
//   2. device.StepPlant(t): the plant and the human over [t, t + dt], holding the drivers' output at t
//      (forward zero-order hold);
//   3. device.SampleStepStart(t): nodes whose frame of t needs the step's acceleration a(t) (the HAL
//      knee's frame torque) sample the instant t;
//   4. on every steps_per_tick-th step: the bus runs to t + dt/2 and the controller ticks there, on the
//      frames sampled at t;
//   5. the bus runs to t + 0.999 dt (the tick's command reaches the driver before t + dt);
//      device.LatchDrivers(t + dt, dt): the drivers' output at t + dt, which the plant holds over the
//      next step (one sample, 1 ms, from sampling to torque);
//   6. t becomes the step's end; device.SampleNodes(t): the nodes sample q(t) and the torque held from t
//      at one instant; then the EMG node samples the electrodes at t and sends one EmgSamples frame;
//   7. device.EndStep(t) (metrics), then, on the log instants (k % log_every == 0), device.LogSample(t).
//   8. a stop request (StopSignal(), core/stop_signal.h: SIGINT / SIGTERM) ends the run here, at the
//      step's end t, as if the schedule ended there.
// Before the first step, device.SampleNodes(0) takes the nodes' samples of the start instant (the EMG
// node's first ADC sample is at dt). The controller sees the plant only through the bus.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "formats/csv_table.h"
#include "hwsim/emg_node.h"
#include "hwsim/virtual_can_bus.h"
#include "protocol/candump.h"
#include "runner/progress_bar.h"
#include "runner/run_bag.h"
#include "runner/runner.h"
#include "runner/scenario.h"
#include "sim/muscles.h"
#include "sim/synthetic_emg.h"

namespace exotwin {

// The device side of one co-simulated trial: plant, human and hardware nodes (on the rig's bus).
class CosimDevice {
 public:
  virtual ~CosimDevice() = default;
  // Step 1: switches that act from t (s).
  virtual void BeginStep(double /*t*/) {}
  // Step 2: advances the plant (and the human) over [t, t + dt] with the drivers' output at t held;
  // returns the plant's own clock at the step's end (s). Throws SimulationError on divergence.
  virtual double StepPlant(double t) = 0;
  // Step 3: nodes that sample the instant t with values the step's computation gives.
  virtual void SampleStepStart(double /*t*/) {}
  // Step 5: the drivers' output at t (s), after the bus delivered the frames sent before t; dt (s) the step.
  virtual void LatchDrivers(double t, double dt) = 0;
  // Step 6: nodes that sample the instant t (the step's end; also t = 0 before the first step).
  virtual void SampleNodes(double /*t*/) {}
  // Step 7: after every step, with the plant at t (metrics).
  virtual void EndStep(double /*t*/) {}
  // Step 7: on the log instants (measured.csv, truth.csv, video, RunOptions::on_sample).
  virtual void LogSample(double /*t*/) {}
};

// The time base of the steps' ends: k dt exactly, or the plant's own clock (StepPlant's result, which
// accumulates dt with rounding).
enum class CosimClock { kGrid, kPlant };

struct CosimSchedule {
  double dt = 1e-3;          // s, physics step
  long steps = 0;            // physics steps of the trial
  int steps_per_tick = 1;    // physics steps per controller tick
  long log_every = 1;        // LogSample on the steps k with k % log_every == 0
  // The rows a trial's logs hold at most (LogSample's instants and the last step's end).
  size_t LogRows() const { return static_cast<size_t>(steps / log_every + 2); }
  CosimClock clock = CosimClock::kGrid;
};

// The schedule of a scenario's trial on a plant of step dt (s): protocol.duration / dt steps, the
// controller at controller.rate_hz, logs at logs.rate_hz. Throws InputError unless the controller's
// rate is the physics rate divided by an integer.
CosimSchedule ScheduleOf(const Scenario& s, double dt, CosimClock clock = CosimClock::kGrid);

// The start of trial `trial` (0-based) on the clock of a run's CAN log and bag, s: the trials follow
// each other, each duration + 1 s after the one before.
double TrialEpoch(const Scenario& s, int trial);

// The virtual CAN bus of a scenario's hardware (bitrate, latency, jitter, drop rate) with `seed`.
hwsim::VirtualCanBusConfig BusConfigOf(const HardwareSpec& hw, uint64_t seed);

// One log of a trial: its CSV file (CsvStreamWriter), with a capture its copy in memory, with a bag
// log its messages in the run's bag (run_bag.h).
class TrialLog {
 public:
  TrialLog(const std::string& path, const std::vector<std::string>& columns, const std::vector<std::string>& comments,
           CapturedLog* capture, std::unique_ptr<BagLog> bag = nullptr);
  // Appends one row: values[0..n), missing columns 0 (CsvStreamWriter::Row); `velocity` (may be null)
  // the bag's measured joint velocities (BagLog::Row).
  void Row(const double* values, size_t n, const double* velocity = nullptr);

 private:
  CsvStreamWriter csv_;
  CapturedLog* capture_;
  std::unique_ptr<BagLog> bag_;
};

// The two logs of trial `trial` (0-based) of `trials`: DIR/measured[_trialN].csv (the rig's view) and
// DIR/truth[_trialN].csv (the plant's), N = trial + 1 when trials > 1, each with `comments`; their
// names are appended to *files, and with `capture` (may be null) their copies in memory to it, room
// made for `rows` rows up front (CosimSchedule::LogRows: the copy then never moves as it grows), and
// with `bag` (may be null) their rows in it too, stamped from `epoch` s (TrialEpoch). Throws InputError
// if a file cannot be opened.
struct TrialLogs {
  std::unique_ptr<TrialLog> measured, truth;
};
TrialLogs OpenTrialLogs(const std::string& dir, int trial, int trials, const std::vector<std::string>& measured_columns,
                        const std::vector<std::string>& truth_columns, const std::vector<std::string>& comments,
                        std::vector<std::string>* files, LogCapture* capture = nullptr, size_t rows = 0,
                        RunBag* bag = nullptr, double epoch = 0);

// Progress of a run over several trials: Run() reports done + k steps to `bar` (may be null).
struct CosimProgress {
  ProgressBar* bar = nullptr;
  size_t done = 0;  // steps of the earlier trials
};

class CosimRig {
 public:
  // A bus with `bus`; with a log (may be null), every frame on the bus is written to it with its time
  // shifted by `epoch` s (successive trials follow each other in one candump file). `log` outlives the rig.
  CosimRig(const hwsim::VirtualCanBusConfig& bus, CandumpWriter* log, double epoch);
  CosimRig(const CosimRig&) = delete;
  CosimRig& operator=(const CosimRig&) = delete;

  // The device adds its nodes here (the order of AddNode decides arbitration ties and draws).
  hwsim::VirtualCanBus& bus() { return bus_; }

  // The human's surface EMG on the bus: at each step's end, the electrodes' voltages (`electrodes`
  // sampling `muscles`' electrical activation) through the amplifier node on `endpoint` (default
  // EmgAmplifierSpec). All three outlive the rig.
  void AttachEmg(CanBus* endpoint, const MuscleModel* muscles, SyntheticEmg* electrodes);
  // The amplifier node (null before AttachEmg).
  const hwsim::EmgNode* emg_node() const { return emg_node_.get(); }

  // Runs schedule.steps steps from t = 0 (the plant and nodes set up at t = 0) in the order of the
  // file comment, fewer if a stop request arrives (step 8); `tick(t)` is the controller's tick at t (s).
  // Returns the time of the last step's end. Begin + Advance(schedule.steps) in one call.
  double Run(const CosimSchedule& schedule, CosimDevice& device, const std::function<void(double)>& tick,
             const CosimProgress& progress = {});
  // The same run in parts (the Python module's steppable twin): Begin takes the start instant's samples
  // (t = 0); each Advance runs up to `steps` more steps of the schedule (fewer at its end or on a stop
  // request) and returns the steps it ran; finished() once the schedule ended or a stop request ended
  // it. Run() and Begin + Advance in any parts run the same steps with the same bits. `device` outlives
  // the run.
  void Begin(const CosimSchedule& schedule, CosimDevice& device);
  long Advance(long steps, const std::function<void(double)>& tick, const CosimProgress& progress = {});
  bool finished() const { return steps_run_ >= schedule_.steps || stopped_by_ != 0; }
  // The time of the last step's end (0 before the first step).
  double time() const { return t_; }
  const CosimSchedule& schedule() const { return schedule_; }
  // The stop signal that ended the run before its schedule's end (2 SIGINT, 15 SIGTERM), 0 when it ran
  // every step so far.
  int stopped_by() const { return stopped_by_; }
  // The steps run so far (schedule.steps at the end unless stopped).
  long steps_run() const { return steps_run_; }

 private:
  hwsim::VirtualCanBus bus_;
  std::unique_ptr<hwsim::EmgNode> emg_node_;
  const MuscleModel* muscles_ = nullptr;
  SyntheticEmg* electrodes_ = nullptr;
  CosimSchedule schedule_;
  CosimDevice* device_ = nullptr;
  double t_ = 0.0;
  int stopped_by_ = 0;
  long steps_run_ = 0;
};

}  // namespace exotwin
