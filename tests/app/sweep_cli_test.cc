// `exotwin sweep` and `exotwin merge`: the shards of a sweep merged are byte for byte the unsharded
// aggregate; the aggregate has one row per subject x scenario; bad input exits 2.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/app/cli_test_util.h"

namespace exotwin::testing {
namespace {

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the scenario";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string Shipped(const std::string& rel) { return std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/" + rel; }

// Two short scenarios (gait 2 s, knee sensor stuck at 1.5 s of 2 s) in dir.
std::string TwoScenarios(const std::string& dir) {
  WriteText(dir + "/gait.yaml", Replace(Replace(testing::ReadText(Shipped("gait_2kmh.yaml")), "duration: 60", "duration: 2"),
                                        "ramp: 2.0", "ramp: 0.5"));
  WriteText(dir + "/stuck.yaml",
            Replace(Replace(testing::ReadText(Shipped("faults/sensor_stuck.yaml")), "duration: 5", "duration: 2"), "at: 3.0",
                    "at: 1.5"));
  return "--scenario " + dir + "/gait.yaml --scenario " + dir + "/stuck.yaml";
}

TEST(SweepCli, ShardedAndMergedEqualsUnsharded) {
  const testing::ScopedTempDir tmp("sweep");
  const std::string dir = tmp.path();
  const std::string sc = TwoScenarios(dir);
  RunResult r = RunExotwin("sweep " + sc + " --subjects 5 --seed 3 --jobs 2 --out " + dir + "/whole");
  ASSERT_LE(r.exit_code, 1) << r.output;
  for (int k = 0; k < 3; ++k) {
    r = RunExotwin("sweep " + sc + " --subjects 5 --seed 3 --jobs 1 --shard " + std::to_string(k) + "/3 --out " +
                   dir + "/part" + std::to_string(k));
    ASSERT_LE(r.exit_code, 1) << r.output;
  }
  r = RunExotwin("merge " + dir + "/part2 " + dir + "/part0 " + dir + "/part1 --out " + dir + "/merged");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"sweep.csv", "summary.json", "sweep.json", "plots/gait_2kmh.svg", "plots/fault_sensor_stuck.svg"}) {
    const std::string a = testing::ReadText(dir + "/whole/" + f), b = testing::ReadText(dir + "/merged/" + f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, b) << f << " differs between the unsharded and the merged sweep";
  }
  // One row per scenario x subject, completed, with subject characteristics and metrics.
  const std::string csv = testing::ReadText(dir + "/whole/sweep.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 10);
  EXPECT_NE(csv.find("subject_weight_kg"), std::string::npos);
  EXPECT_NE(csv.find("tracking_rms_knee_deg"), std::string::npos);
  EXPECT_EQ(csv.find("wall_time_s"), std::string::npos);
  EXPECT_EQ(csv.find("diverged"), std::string::npos);
  const auto j = nlohmann::json::parse(testing::ReadText(dir + "/whole/summary.json"));
  const auto& st = j["scenarios"]["gait_2kmh"]["metrics"]["tracking_rms_hip_deg"];
  EXPECT_EQ(st["n"], 5);
  for (const char* k : {"mean", "sd", "min", "max", "p5", "p95"}) EXPECT_TRUE(st.contains(k)) << k;
  EXPECT_LE(st["min"].get<double>(), st["p5"].get<double>());
  EXPECT_LE(st["p95"].get<double>(), st["max"].get<double>());
  EXPECT_GT(st["sd"].get<double>(), 0.0);  // the subjects differ
  // The part holds only its own subjects.
  EXPECT_EQ(testing::ReadText(dir + "/part1/sweep.json").find("\"shard\": \"1/3\"") != std::string::npos, true);
}

TEST(SweepCli, BadInputExits2) {
  const testing::ScopedTempDir tmp("sweep_bad");
  const std::string dir = tmp.path();
  const std::string sc = TwoScenarios(dir);
  for (const std::string& args :
       {sc + " --subjects 3 --shard 3/3 --out " + dir + "/o", sc + " --subjects 0 --out " + dir + "/o",
        sc + " --subjects 2 --shard x --out " + dir + "/o", "--scenario " + dir + "/none.yaml --subjects 2 --out " + dir,
        "--scenario " + dir + "/gait.yaml --scenario " + dir + "/gait.yaml --subjects 2 --out " + dir + "/o"}) {
    const RunResult r = RunExotwin("sweep " + args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
  }
  // Merge: a missing shard, and a folder that is not a sweep.
  RunResult r = RunExotwin("sweep --scenario " + dir + "/gait.yaml --subjects 2 --shard 0/2 --out " + dir + "/p0");
  ASSERT_LE(r.exit_code, 1) << r.output;
  r = RunExotwin("merge " + dir + "/p0 --out " + dir + "/m");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing shard(s) 1/2"), std::string::npos) << r.output;
  r = RunExotwin("merge " + dir + "/nothing --out " + dir + "/m");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

}  // namespace
}  // namespace exotwin::testing
