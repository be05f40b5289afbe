// The EXOwheel closed-loop runner (device exowheel or exowheel_exo_only): per trial, the MuJoCo leg +
// exoskeleton, the joint modules and the subject's muscles and EMG on the co-simulation rig
// (runner/cosim_rig.h) with the real ExoController tracking the protocol's trajectory (gait,
// identification excitation or hold); faults switch on and off as the scenario says.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "runner/runner.h"

namespace exotwin {

// Runs every trial of an EXOwheel scenario (RunScenario's dispatch): writes DIR/result.json,
// DIR/measured[_trialN].csv (the rig's view: encoder angles, torque-sensor readings, commands, EMG)
// and DIR/truth[_trialN].csv (plant state, applied and muscle torques); with opt.video_path, the
// first trial's video. Throws InputError on bad scenario content and SimulationError on divergence.
RunResult RunExowheelScenario(const Scenario& s, const RunOptions& opt);

// An EXOwheel run advanced from outside, a few physics steps at a time (the Python module's Twin,
// python/module_twin.cc), optionally with the control law's output given for the controller's ticks;
// RunExowheelScenario is one session advanced to its end. The same steps with no command give the same
// bits, logs and result as RunExowheelScenario, however the run is cut into Advance calls.
class ExowheelSession {
 public:
  // Sets the run up as RunExowheelScenario does (plant, first trial at t = 0). `s` and `opt` are copied.
  // Throws InputError on bad scenario content.
  ExowheelSession(const Scenario& s, const RunOptions& opt);
  ~ExowheelSession();
  ExowheelSession(const ExowheelSession&) = delete;
  ExowheelSession& operator=(const ExowheelSession&) = delete;

  // Runs up to `steps` physics steps, from one trial into the next; `command` (N m, hip then knee; may
  // be null) replaces the controller's control law at the ticks in them (ExoController::Tick; the safety
  // supervisor still acts). Returns the steps run (fewer once done()). Throws SimulationError on
  // divergence.
  long Advance(long steps, const double* command);
  // Every trial ran, or a stop request (SIGINT / SIGTERM) ended the run.
  bool done() const;
  int steps_per_tick() const;  // physics steps per controller period
  int trial() const;           // the trial running (0-based)
  double time() const;         // s, the trial's time at the last step's end
  // measured.csv's and truth.csv's columns, and their rows at the last step's end (what LogSample writes
  // on a log instant); the rows' values go to row[0 .. returned count).
  std::vector<std::string> MeasuredColumns() const;
  std::vector<std::string> TruthColumns() const;
  size_t MeasuredRow(double* row) const;
  size_t TruthRow(double* row) const;
  int safety_state() const;  // the controller's safety state (controller::SafetyState)
  // Ends the run (once): metrics, checks and result.json, as RunExowheelScenario.
  RunResult Finish();

 private:
  struct State;
  std::unique_ptr<State> st_;
};

}  // namespace exotwin
