// Contract of the scenario fuzz target, shared with tests/runner/corpus_replay_test.cc: a scenario
// either parses or throws InputError (its checks' metrics included: runner/scenario_metrics.h); one
// that parses goes on to the end of a run as `run` ends it (FinishRun: the checks evaluated on
// metrics, result.json written), without a plant: result.json must be valid text and JSON, and
// FinishRun must throw nothing, since every check names a metric the run reports.
#pragma once
#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/file_text.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin::fuzz {

// A plant file (a model file's effect list, as data/plants/*.yaml) the corpus's scenarios name as
// plant.yaml beside them.
inline constexpr const char* kPlantFile =
    "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\npassive: none\neffects:\n"
    "  - {name: sensor_offset, joint: hip, value: 0.12, unit: \"N m\"}\n"
    "  - {name: coulomb_friction, joint: knee, value: 0.4, unit: \"N m\"}\n";

// `text` as a scenario file at dir/fuzz.yaml (its relative paths, e.g. plant.effects_from, from dir).
// Returns true if it parsed.
inline bool ScenarioText(const std::string& text, const std::string& dir) {
  Scenario s;
  try {
    s = ParseScenarioYaml(text, dir + "/fuzz.yaml");
  } catch (const InputError&) {
    return false;
  }
  RunResult r;
  r.scenario = s.name;
  r.seed = s.seed;
  double v = 0;
  for (const CheckSpec& c : s.checks) r.metrics[c.metric] = v++;  // what the runner reports for them
  r.metrics["wall_time_s"] = 0.5;
  r.events.push_back("t=0.1 " + (s.faults.empty() ? std::string("none") : s.faults[0].type));
  const std::string path = dir + "/result.json";
  FinishRun(s, r, path);  // must not throw
  const std::string written = ReadTextFile(path, "", "the result.json just written");
  if (const auto f = FindTextFault(written)) throw std::logic_error("result.json: not valid text: " + f->Where());
  const nlohmann::json j = nlohmann::json::parse(written);  // must parse
  if (j.at("checks").size() != s.checks.size() || j.at("scenario").get<std::string>() != s.name)
    throw std::logic_error("result.json: does not hold the scenario's checks");
  return true;
}

}  // namespace exotwin::fuzz
