// The metrics a scenario's run reports, known when it is read: every metric the shipped scenarios'
// runs reported (their regression baselines, scenarios/baselines/*.json) is one its scenario
// accepts, and a check naming another is refused when the scenario is read.
#include "runner/scenario_metrics.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

const std::filesystem::path kScenarios = std::filesystem::path(EXOTWIN_SOURCE_DIR) / "scenarios";

TEST(ScenarioMetrics, EveryMetricOfTheShippedRunsIsKnownBeforeTheRun) {
  int baselines = 0;
  for (const auto& e : std::filesystem::directory_iterator(kScenarios / "baselines")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    const nlohmann::json b = nlohmann::json::parse(in);
    const Scenario s = ReadScenario((kScenarios / b.at("source").get<std::string>()).string());
    for (const auto& m : b.at("metrics").items())
      EXPECT_TRUE(IsScenarioMetric(s, m.key())) << e.path().filename() << ": " << m.key();
    ++baselines;
  }
  EXPECT_GE(baselines, 15);
}

Scenario Parse(const std::string& body) {
  return ParseScenarioYaml("name: m\ndevice: exowheel\nsubject: {preset: S1}\n" + body, "m.yaml");
}

std::string MessageOf(const std::string& body) {
  try {
    Parse(body);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ScenarioMetrics, ACheckTheRunCannotJudgeIsRefusedWhenRead) {
  EXPECT_NO_THROW(Parse("checks:\n  - {metric: tracking_rms_hip_deg, max: 1}\n  - {metric: link_late_cycles, max: 0}\n"));
  const std::string m = MessageOf("checks:\n  - {metric: samples, min: 1}\n  - {metric: tracking_rms_hip_dg, max: 1}\n");
  EXPECT_EQ(m.rfind("m.yaml: checks[1].metric: unknown metric 'tracking_rms_hip_dg' for an EXOwheel scenario "
                    "(expected one of: samples, tracking_rms_hip_deg, ",
                    0),
            0u)
      << m;
  // HAL-3: assist mode's RLS and a sweep's per-value criteria only where the run reports them.
  const std::string hal = "name: h\ndevice: hal3\nsubject: {preset: S1}\n";
  EXPECT_THROW(ParseScenarioYaml(hal + "checks: [{metric: rls_K_err_pct, max: 1}]\n", "h.yaml"), InputError);
  EXPECT_NO_THROW(ParseScenarioYaml(hal + "hal: {mode: assist}\nchecks: [{metric: rls_K_err_pct, max: 1}]\n", "h.yaml"));
  EXPECT_THROW(ParseScenarioYaml(hal + "checks: [{metric: J_tau_m@1, max: 1}]\n", "h.yaml"), InputError);
  EXPECT_NO_THROW(ParseScenarioYaml(hal + "hal: {sweep_viscosity: [0, 1]}\nchecks: [{metric: J_tau_m@1, max: 1}]\n", "h.yaml"));
  // A name of any length is matched without recursion.
  EXPECT_THROW(Parse("checks: [{metric: link" + std::string(1 << 16, 'x') + "y_, max: 1}]\n"), InputError);
}

}  // namespace
}  // namespace exotwin
