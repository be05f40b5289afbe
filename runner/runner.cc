// RunScenario's dispatch to the device runners, the scenario's subject, and the end of a run
// (checks, result.json): see runner.h.
#include "runner/runner.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>

#include "formats/csv_table.h"
#include "formats/model_file.h"
#include "core/error.h"
#include "core/stop_signal.h"
#include "runner/emg_calibration_protocol.h"
#include "runner/exowheel_runner.h"
#include "runner/hal_runner.h"
#include "sim/mjcf_cache.h"
#include "sim/muscles.h"
#include "sim/plant.h"
#include "sim/subjects.h"

namespace exotwin {

bool RunResult::all_passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.passed; });
}

std::optional<Subject> ScenarioSubject(const Scenario& s) {
  if (!s.subject.preset.empty()) return PresetSubject(s.subject.preset);
  if (s.subject.random_seed) return DrawSubject(*s.subject.random_seed, 0);
  return std::nullopt;
}

ContractionProgramme IsometricProgrammeOf(const HumanSpec& h, uint64_t run_seed) {
  return IsometricProgramme(h.behaviour == "isometric_hip" ? 0 : 1, h.contractions, h.levels[0], h.levels[1],
                            h.cocontraction, h.programme_seed ? *h.programme_seed : run_seed);
}

LegParams ResolveSubject(const Scenario& s) {
  LegParams p;
  if (!s.subject.params_file.empty()) {
    p = ReadModelFile(s.subject.params_file);
  } else if (!s.subject.preset.empty()) {
    p = SubjectLegParams(PresetSubject(s.subject.preset));
  } else if (s.subject.random_seed) {
    p = SubjectLegParams(DrawSubject(*s.subject.random_seed, 0));
  } else {
    // Exo-only scenario without a subject: the mean exoskeleton of Table 3 at L1 = 0.41 m.
    p.L1 = 0.41;
    p.exo = {3.01, 0.74, 3.85, 1.73, 0.14, 0.18};
  }
  if (s.device == Device::kExowheelExoOnly) {
    p.human.reset();
    p.passive = PassiveModel::kNone;
  } else if (s.subject.params_file.empty()) {
    p.passive = s.subject.passive;
  }
  return p;
}

void KeepScenarioModel(const Scenario& s) {
  KeepMjcfModel(s.device == Device::kHal3 ? ShippedModelPath("hal3_knee.xml")
                                          : ExowheelMjcfPath(s.device != Device::kExowheelExoOnly));
}

RunResult RunScenario(const Scenario& s, const RunOptions& opt) {
  if (s.device == Device::kHal3) return RunHalScenario(s, opt);
  if (s.emg_calibration) return RunEmgCalibrationScenario(s, opt);
  return RunExowheelScenario(s, opt);
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
