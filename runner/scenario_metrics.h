// The metrics a scenario's run reports, known before it runs, so that a check naming a metric the
// run cannot report is refused when the scenario is read, not after the run was spent on it.
#pragma once
#include <string>
#include <vector>

#include "runner/scenario.h"

namespace exotwin {

// The names (patterns: '*' stands for any text) of the metrics the runner of `s` (runner.h
// RunScenario) can report: the EXOwheel closed loop's, the HAL-3 runner's (with assist mode's RLS and
// a viscosity sweep's per-value criteria), the EMG calibration protocol's (per muscle, joint, parameter
// set and subject: by prefix); everywhere `wall_time_s` and the controller link's `link_*` (serve,
// regress --controller-process).
std::vector<std::string> ScenarioMetricPatterns(const Scenario& s);

// Whether the run of `s` can report `metric`.
bool IsScenarioMetric(const Scenario& s, const std::string& metric);

// Throws InputError "<source>: checks[i].metric: unknown metric 'x' for <kind> (expected one of: ...)"
// for the first check whose metric the run of `s` cannot report.
void CheckScenarioMetrics(const Scenario& s);

}  // namespace exotwin
