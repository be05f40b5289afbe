// One scenario run as a job of a forked pool (fork_pool.h): the child runs the scenario into its
// folder and leaves result.json (or error.txt); the parent reads the outcome back from the folder.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "batch/fork_pool.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {

// Exit codes of a scenario job (the child's exit code).
enum JobExit : int { kJobOk = 0, kJobCheckFailed = 1, kJobInputError = 2, kJobDiverged = 3 };

// Runs `s` into opt.out_dir (created) with RunScenario (with opt.controller_process:
// RunWithControllerProcess); returns a JobExit. On InputError / SimulationError /
// another exception, writes the message to out_dir/error.txt instead of throwing. Meant for the child.
int RunScenarioJob(const Scenario& s, const RunOptions& opt);

// What a finished job left behind.
struct JobRun {
  std::string status;  // "ok", "check_failed", "input_error", "diverged", "crashed"
  std::string error;   // message of error.txt / signal, empty when the run completed
  std::map<std::string, double> metrics;  // from result.json (empty unless the run completed)
  std::vector<CheckResult> checks;
  bool completed() const { return status == "ok" || status == "check_failed"; }
};

// Reads dir/result.json (or dir/error.txt) of a job with outcome `o`.
JobRun ReadJobRun(const std::string& dir, const JobOutcome& o);

// True for metrics that are bit-reproducible from the scenario and seed (all but wall_time_s and the
// controller link's link_* figures).
bool IsDeterministicMetric(const std::string& name);

}  // namespace exotwin
