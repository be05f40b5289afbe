// The regression gate's pieces: tolerances and verdicts (scenarios/metric_tolerance.h), baseline
// files (scenarios/baseline.h), suite listing and evaluation (scenarios/regress.h).
#include "tests/temp_dir.h"
#include "batch/regress.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace exotwin {
namespace {


const MetricDelta& Find(const std::vector<MetricDelta>& v, const std::string& m) {
  for (const auto& d : v)
    if (d.metric == m) return d;
  throw std::runtime_error("no metric " + m);
}

TEST(MetricTolerance, VerdictsByKind) {
  const std::map<std::string, double> base = {{"tracking_rms_hip_deg", 0.40}, {"torque_max_hip", 50.0},
                                              {"frames", 40000}, {"samples", 4000}, {"bus_load_pct", 30},
                                              {"gone", 1}};
  std::map<std::string, double> now = base;
  now.erase("gone");
  now["tracking_rms_hip_deg"] = 0.40 + 0.011;  // 3 % of 0.4 = 0.012: within
  now["torque_max_hip"] = 52.0;                // 2 % of 50 = 1.0: beyond, no better direction
  now["samples"] = 4001;                       // exact
  now["brand_new"] = 3;
  auto d = CompareMetrics(base, now);
  EXPECT_EQ(Find(d, "tracking_rms_hip_deg").verdict, Verdict::kWithin);
  EXPECT_NEAR(Find(d, "tracking_rms_hip_deg").tolerance, 0.012, 1e-12);
  EXPECT_EQ(Find(d, "torque_max_hip").verdict, Verdict::kChanged);
  EXPECT_EQ(Find(d, "frames").verdict, Verdict::kSame);
  EXPECT_EQ(Find(d, "samples").verdict, Verdict::kChanged);
  EXPECT_EQ(Find(d, "gone").verdict, Verdict::kMissing);
  EXPECT_EQ(Find(d, "brand_new").verdict, Verdict::kNew);
  EXPECT_FALSE(IsFailure(Verdict::kNew));

  now["tracking_rms_hip_deg"] = 0.80;
  EXPECT_EQ(Find(CompareMetrics(base, now), "tracking_rms_hip_deg").verdict, Verdict::kRegressed);
  now["tracking_rms_hip_deg"] = 0.20;
  EXPECT_EQ(Find(CompareMetrics(base, now), "tracking_rms_hip_deg").verdict, Verdict::kImproved);
  EXPECT_FALSE(IsFailure(Verdict::kImproved));
  // An override widens the tolerance.
  now["tracking_rms_hip_deg"] = 0.80;
  EXPECT_EQ(Find(CompareMetrics(base, now, {{"tracking_rms_hip_deg", {0.5, 0}}}), "tracking_rms_hip_deg").verdict,
            Verdict::kWithin);
}

TEST(MetricTolerance, NanEqualsNan) {
  const auto d = CompareMetrics({{"x", std::nan("")}}, {{"x", std::nan("")}});
  EXPECT_EQ(d[0].verdict, Verdict::kSame);
  EXPECT_EQ(CompareMetrics({{"x", std::nan("")}}, {{"x", 1.0}})[0].verdict, Verdict::kChanged);
}

TEST(Baseline, RoundTripKeepsBitsAndOverrides) {
  const testing::ScopedTempDir tmp("regress_baseline");
  const std::string dir = tmp.path();
  Baseline b;
  b.scenario = "gait";
  b.source = "gait.yaml";
  b.seed = 7;
  b.metrics = {{"a", 0.1 + 0.2}, {"b", -1.0 / 3.0}, {"c", std::nan("")}};
  b.tolerance = {{"a", {0.5, 0.01}}};
  WriteBaseline(b, dir + "/sub/gait.json");
  const Baseline r = ReadBaseline(dir + "/sub/gait.json");
  EXPECT_EQ(r.scenario, "gait");
  EXPECT_EQ(r.seed, 7u);
  EXPECT_EQ(r.metrics.at("a"), 0.1 + 0.2);
  EXPECT_EQ(r.metrics.at("b"), -1.0 / 3.0);
  EXPECT_TRUE(std::isnan(r.metrics.at("c")));
  EXPECT_EQ(r.tolerance.at("a").abs, 0.5);
  EXPECT_EQ(r.tolerance.at("a").rel, 0.01);
}

TEST(Baseline, BadContentNamesFileAndField) {
  const testing::ScopedTempDir tmp("regress_bad_baseline");
  const std::string dir = tmp.path();
  std::ofstream(dir + "/x.json") << R"({"metrics": {"a": 1}, "tolerance": {"a": {"abs": -1}}})";
  try {
    ReadBaseline(dir + "/x.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("tolerance.a.abs"), std::string::npos);
  }
  std::ofstream(dir + "/y.json") << R"({"metrics": {"a": "high"}})";
  EXPECT_THROW(ReadBaseline(dir + "/y.json"), InputError);
}

TEST(Suite, ListsRecursivelySkipsBaselinesRejectsDuplicateNames) {
  const testing::ScopedTempDir tmp("regress_suite");
  const std::string dir = tmp.path();
  std::filesystem::create_directories(dir + "/faults");
  std::filesystem::create_directories(dir + "/baselines");
  const std::string body = "device: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: hold, duration: 1}\n";
  std::ofstream(dir + "/b.yaml") << "name: b\n" << body;
  std::ofstream(dir + "/faults/a.yaml") << "name: a\n" << body;
  std::ofstream(dir + "/baselines/ignored.yaml") << "not: a scenario\n";
  const auto suite = ListSuite(dir);
  ASSERT_EQ(suite.size(), 2u);
  EXPECT_EQ(suite[0].relative, "b.yaml");
  EXPECT_EQ(suite[1].relative, "faults/a.yaml");
  std::ofstream(dir + "/c.yaml") << "name: b\n" << body;
  EXPECT_THROW(ListSuite(dir), InputError);
  EXPECT_THROW(ListSuite(dir + "/nope"), InputError);
}

TEST(Suite, EvaluateFlagsMissingBaselineAndFailedChecks) {
  const testing::ScopedTempDir tmp("regress_evaluate");
  const std::string dir = tmp.path();
  SuiteEntry e;
  e.scenario.name = "s";
  e.relative = "s.yaml";
  JobRun run;
  run.status = "ok";
  run.metrics = {{"tracking_rms_hip_deg", 0.5}, {"wall_time_s", 3.0}};
  ScenarioRegression r = EvaluateRegression(e, run, dir);
  EXPECT_FALSE(r.has_baseline);
  EXPECT_TRUE(r.failed());
  WriteBaseline(BaselineFromRun(e, run, nullptr), dir + "/s.json");
  EXPECT_EQ(ReadBaseline(dir + "/s.json").metrics.count("wall_time_s"), 0u);  // not deterministic
  run.metrics["wall_time_s"] = 9.0;
  r = EvaluateRegression(e, run, dir);
  EXPECT_FALSE(r.failed());
  CheckResult c;
  c.name = "limit";
  c.passed = false;
  run.checks.push_back(c);
  run.status = "check_failed";
  EXPECT_TRUE(EvaluateRegression(e, run, dir).failed());
}

}  // namespace
}  // namespace exotwin
