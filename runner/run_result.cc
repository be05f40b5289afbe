// The end of a run: its checks and result.json (runner.h). Apart from the runners, so that the fuzz
// targets (fuzz/) write what `run` writes from a parsed scenario without a plant.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>

#include "core/error.h"
#include "core/stop_signal.h"
#include "formats/csv_table.h"
#include "runner/runner.h"

namespace exotwin {

bool RunResult::all_passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.passed; });
}

namespace {

// The checks on `m`; a check whose metric is missing is failed with value NaN and named in *unknown.
std::vector<CheckResult> Checks(const Scenario& s, const std::map<std::string, double>& m,
                                std::string* unknown) {
  std::vector<CheckResult> out;
  for (const CheckSpec& c : s.checks) {
    CheckResult r;
    r.name = c.name;
    r.metric = c.metric;
    r.op = c.op;
    r.limit = c.limit;
    auto it = m.find(c.metric);
    if (it == m.end()) {
      if (unknown->empty()) {
        std::string list;
        for (const auto& kv : m) list += (list.empty() ? "" : ", ") + kv.first;
        *unknown = s.source + ": checks: unknown metric '" + c.metric + "', expected one of: " + list;
      }
      r.value = std::numeric_limits<double>::quiet_NaN();
      r.passed = false;
    } else {
      r.value = it->second;
      r.passed = c.op == "<=" ? r.value <= c.limit : r.value >= c.limit;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace

void FinishRun(const Scenario& s, RunResult& result, const std::string& path) {
  std::string unknown;
  result.checks = Checks(s, result.metrics, &unknown);
  if (result.interrupted) {
    for (CheckResult& c : result.checks) c.passed = false;
    unknown.clear();
  }
  WriteResultJson(result, path);
  if (!unknown.empty()) throw InputError(unknown + " (the run's metrics are in " + path + ")");
}

void WriteResultJson(const RunResult& r, const std::string& path) {
  nlohmann::json j;
  j["scenario"] = r.scenario;
  j["seed"] = r.seed;
  j["checks"] = nlohmann::json::array();
  for (const CheckResult& c : r.checks)
    j["checks"].push_back({{"name", c.name}, {"metric", c.metric}, {"op", c.op}, {"passed", c.passed},
                           {"value", c.value}, {"limit", c.limit}});
  j["metrics"] = nlohmann::json::object();
  for (const auto& kv : r.metrics) j["metrics"][kv.first] = kv.second;
  j["files"] = r.files;
  j["events"] = r.events;
  if (r.interrupted)
    j["interrupted"] = {{"signal", r.interrupted->signal},
                        {"name", StopSignalName(r.interrupted->signal)},
                        {"t_s", r.interrupted->t},
                        {"trial", r.interrupted->trial}};
  WriteFileAtomic(path, j.dump(2) + "\n");
}

}  // namespace exotwin
