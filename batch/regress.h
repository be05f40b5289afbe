// The controller-regression gate (`exotwin regress`): runs a suite of scenarios and compares each
// one's deterministic metrics with its baseline (baseline.h) within per-metric tolerances.
#pragma once
#include <string>
#include <vector>

#include "batch/baseline.h"
#include "batch/metric_tolerance.h"
#include "runner/scenario.h"
#include "batch/scenario_job.h"

namespace exotwin {

struct SuiteEntry {
  std::string path;      // scenario file
  std::string relative;  // path relative to the suite folder (for messages and baselines)
  Scenario scenario;
};

// Every *.yaml under `dir` (recursively, sorted by path; the `baselines` folder and files starting
// with '.' skipped), parsed. Throws InputError if dir is not a folder, holds no scenario, a file does
// not parse, or two scenarios share a name (the baseline key).
std::vector<SuiteEntry> ListSuite(const std::string& dir);

// The verdict of one scenario of the suite.
struct ScenarioRegression {
  std::string name, source, baseline_path;
  bool has_baseline = false;
  JobRun run;                         // status, metrics and checks of this run
  std::vector<MetricDelta> deltas;    // deterministic metrics only; empty without a baseline
  std::vector<CheckResult> failed_checks;
  bool regressed() const;             // a metric moved beyond tolerance (the wrong way) or is missing
  bool failed() const;                // regressed, a check failed, no baseline, or the run failed
};

// Compares a finished run with baseline_dir/<name>.json (absent: has_baseline = false).
// Throws InputError if the baseline file exists but is malformed.
ScenarioRegression EvaluateRegression(const SuiteEntry& e, const JobRun& run, const std::string& baseline_dir);

// The baseline that records this run (keeps the tolerance overrides of `previous` if given).
Baseline BaselineFromRun(const SuiteEntry& e, const JobRun& run, const Baseline* previous);

// Human-readable table: one line per metric that moved (all metrics with show_all), per scenario a
// status line; ends with a summary line. Plain text, no colours.
std::string FormatRegressionReport(const std::vector<ScenarioRegression>& results, bool show_all);

// Machine-readable report (regress.json): per scenario status, failed checks and every delta.
std::string RegressionJson(const std::vector<ScenarioRegression>& results);

}  // namespace exotwin
