// The scenario runner: builds the twin (plant + virtual hardware + the real controller) from a
// scenario, runs it in lockstep on the co-simulation rig (runner/cosim_rig.h), logs the measured
// data, computes metrics and evaluates the checks. RunScenario is the one place that chooses the
// device runner for a scenario.
#pragma once
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "model/lumped_params.h"
#include "runner/scenario.h"
#include "sim/muscles.h"
#include "sim/subjects.h"

namespace exotwin {

class RemoteController;  // runner/remote_controller.h

// A log of a run kept in memory as it is written (RunOptions::capture; the Python module's results):
// the numbers of the rows its CSV file holds (the file's text reads back to these doubles bit for bit,
// AppendNumber), row-major.
struct CapturedLog {
  std::string file;                  // the CSV file's name in the run's folder: measured.csv, truth_trial2.csv
  std::vector<std::string> columns;  // its header
  std::vector<double> values;        // rows * columns.size(), row-major
  size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
};
// The logs of a run in the order they were opened (a deque: a log keeps its address while more are added).
using LogCapture = std::deque<CapturedLog>;

struct RunOptions {
  std::string out_dir = "out";
  std::optional<uint64_t> seed;  // overrides the scenario's seed
  std::string can_log;           // candump log of every frame on the bus ("" = none)
  std::string mcap;              // the run's logs as a ROS 2 bag (run_bag.h; "" = none)
  bool progress = false;         // progress bar on stderr
  std::string video_path;        // MP4 of the first trial (side view + overlays); "" = none
  // Called once per logged sample with (t, q_true[2], tau_applied[2]) (e.g. a video renderer).
  std::function<void(double, const double*, const double*)> on_sample;
  // The controller in another process (`exotwin serve`, RunWithControllerProcess): the device runners
  // set its configuration per run or trial and tick it instead of the in-process controller; the
  // session's end (RemoteController::EndRun) is the owner's. Null: in-process.
  RemoteController* remote = nullptr;
  // RunScenarioJob (scenario_job.h) only: the exotwin-controller executable to run the scenario's
  // controller in another process (RunWithControllerProcess, controller_process.h); "" = in-process.
  std::string controller_process;
  // The logs kept in memory too (measured and truth of every trial, as their CSV files hold them; the
  // Python module's results); null: files only.
  LogCapture* capture = nullptr;
};

struct CheckResult {
  std::string name, metric, op;
  double value = 0, limit = 0;
  bool passed = false;
};

// A run ended early by a stop request (SIGINT / SIGTERM, core/stop_signal.h).
struct RunInterruption {
  int signal = 0;   // 2 SIGINT, 15 SIGTERM
  double t = 0;     // s, simulated time reached in the interrupted trial (its last step's end)
  int trial = 1;    // the interrupted trial (1-based; HAL sweeps: the value's run)
};

struct RunResult {
  std::string scenario;
  uint64_t seed = 0;
  std::map<std::string, double> metrics;
  std::vector<CheckResult> checks;
  std::vector<std::string> files;  // written files
  std::vector<std::string> events; // fault events "t=... type joint"
  std::optional<RunInterruption> interrupted;  // set when a stop request ended the run early
  bool all_passed() const;
};

// The subject's parameters as the twin's ground truth (preset, population draw or MODEL.yaml),
// with the scenario's passive model; exo alone for the exo-only device.
LegParams ResolveSubject(const Scenario& s);

// The subject's characteristics (weight, segment lengths) for a preset or population draw; none for a
// MODEL.yaml subject or the exo alone.
std::optional<Subject> ScenarioSubject(const Scenario& s);

// The contraction programme of an isometric_hip / isometric_knee behaviour (h.programme_seed, else
// run_seed): the runner plays it, and the EMG calibration protocol reads its blocks (s, fraction of MVC).
ContractionProgramme IsometricProgrammeOf(const HumanSpec& h, uint64_t run_seed);

// Everything the run of `s` with `opt` reads or writes besides the scenario file, checked before
// anything runs: the subject's model file, the effects the plant carries (as the plant takes them),
// the recorded trajectory of trajectory: file, an empty or folder video path, a bag (opt.mcap) that is a
// folder or of a scenario that logs no rows (an emg_calibration protocol, logs.measured_csv false); the
// folders of the outputs (out_dir, video, CAN log, bag) are created. Throws InputError. RunScenario calls it first; sweep
// and regress call it for every job before the first job starts. (The check metrics are checked
// when the scenario is read: runner/scenario_metrics.h.)
void CheckScenarioRun(const Scenario& s, const RunOptions& opt);

// Runs the scenario with the runner of its kind: device hal3 -> RunHalScenario (hal_runner.h); an
// emg_calibration block -> RunEmgCalibrationScenario (emg_calibration_protocol.h); otherwise the
// EXOwheel closed loop (gait, identification excitation or hold) -> RunExowheelScenario
// (exowheel_runner.h), after CheckScenarioRun. Each writes DIR/result.json, DIR/measured[_trialN].csv (the rig's view:
// encoder angles, torque-sensor readings, commands) and DIR/truth[_trialN].csv (plant state and applied
// torque). Throws InputError on bad scenario content and SimulationError on divergence (the logs
// written so far stay on disk).
RunResult RunScenario(const Scenario& s, const RunOptions& opt);

// Keeps (sim/mjcf_cache.h) the MuJoCo model the scenario's runner loads, so that runs forked after
// this call (sweep and regression workers) copy it instead of loading the MJCF file again.
void KeepScenarioModel(const Scenario& s);

// End of a run: evaluates the checks on result.metrics, writes result.json at `path`, then throws
// InputError if a check names a metric the run did not produce (that check is written as failed with
// value null, so the metrics of a long run are kept on disk before the exit code 2). An interrupted run
// (result.interrupted) fails every check (value: the metric over the part that ran) and throws nothing:
// a check holds for the whole scenario, which did not run.
void FinishRun(const Scenario& s, RunResult& result, const std::string& path);

// Writes result.json (atomically).
void WriteResultJson(const RunResult& r, const std::string& path);

}  // namespace exotwin
