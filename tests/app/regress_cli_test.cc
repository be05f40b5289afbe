// `exotwin regress`: the gate passes an unchanged controller, catches a detuned gain (kp halved ->
// tracking error beyond tolerance -> exit 1), fails on a failed check, and rejects bad input (exit 2).
// The suite is a temporary copy of shipped scenarios with shortened durations.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/app/cli_test_util.h"

namespace exotwin::testing {
namespace {

// Replaces the first `from` by `to`; fails the test if `from` is absent.
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the scenario";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// True if a line of `text` starts with `head` and contains `part`.
bool HasLine(const std::string& text, const std::string& head, const std::string& part) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(head, 0) == 0 && line.find(part) != std::string::npos) return true;
  return false;
}

std::string Shipped(const std::string& rel) { return std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/" + rel; }

// Gait at 4 s (1 s ramp) instead of 60 s.
std::string ShortGait() {
  return Replace(Replace(testing::ReadText(Shipped("gait_2kmh.yaml")), "duration: 60", "duration: 4"), "ramp: 2.0", "ramp: 1.0");
}

TEST(RegressCli, UnchangedControllerPassesDetunedGainIsCaught) {
  const testing::ScopedTempDir tmp("regress");
  const std::string dir = tmp.path(), suite = dir + "/suite";
  std::filesystem::create_directories(suite + "/faults");
  const std::string gait = ShortGait();
  WriteText(suite + "/gait_2kmh.yaml", gait);
  std::filesystem::copy_file(Shipped("faults/sensor_stuck.yaml"), suite + "/faults/sensor_stuck.yaml");

  RunResult r = RunExotwin("regress --suite " + suite + " --update --jobs 2 --out " + dir + "/o1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(std::filesystem::exists(suite + "/baselines/gait_2kmh.json")) << r.output;
  ASSERT_TRUE(std::filesystem::exists(suite + "/baselines/fault_sensor_stuck.json"));
  EXPECT_EQ(testing::ReadText(suite + "/baselines/gait_2kmh.json").find("wall_time_s"), std::string::npos);

  r = RunExotwin("regress --suite " + suite + " --out " + dir + "/o2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 scenarios, 0 failed"), std::string::npos) << r.output;

  // Detuned: position gains halved. The tracking error grows far beyond its 3 % tolerance.
  WriteText(suite + "/gait_2kmh.yaml", Replace(gait, "kp: [600, 400]", "kp: [300, 200]"));
  r = RunExotwin("regress --suite " + suite + " --out " + dir + "/o3");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("tracking_rms_hip_deg"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("tracking_rms_knee_deg"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("REGRESSED"), std::string::npos) << r.output;
  EXPECT_TRUE(HasLine(r.output, "fault_sensor_stuck", " ok (")) << r.output;  // the other scenario passes
  const std::string report = testing::ReadText(dir + "/o3/regress.json");
  EXPECT_NE(report.find("\"passed\": false"), std::string::npos);

  // Restored: passes again (the baselines were not touched by the failing run).
  WriteText(suite + "/gait_2kmh.yaml", gait);
  r = RunExotwin("regress --suite " + suite + " --out " + dir + "/o4");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(RegressCli, FailedCheckOrMissingBaselineExits1) {
  const testing::ScopedTempDir tmp("regress_check");
  const std::string dir = tmp.path(), suite = dir + "/suite";
  std::filesystem::create_directories(suite);
  const std::string hold =
      "name: hold\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: hold, duration: 1, ramp: 0.2}\n"
      "checks:\n  - {name: impossible, metric: tracking_rms_hip_deg, max: -1}\n";
  WriteText(suite + "/hold.yaml", hold);
  RunResult r = RunExotwin("regress --suite " + suite + " --out " + dir + "/o1");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("NO BASELINE"), std::string::npos) << r.output;
  r = RunExotwin("regress --suite " + suite + " --update --out " + dir + "/o2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunExotwin("regress --suite " + suite + " --out " + dir + "/o3");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("check FAILED: impossible"), std::string::npos) << r.output;
}

TEST(RegressCli, BadInputExits2) {
  const testing::ScopedTempDir tmp("regress_bad");
  const std::string dir = tmp.path();
  RunResult r = RunExotwin("regress --suite " + dir + "/missing");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing"), std::string::npos);
  WriteText(dir + "/broken.yaml", "name: x\nprotocol: {duration: -3}\n");
  r = RunExotwin("regress --suite " + dir + " --out " + dir + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("broken.yaml"), std::string::npos) << r.output;
  // A malformed baseline file is bad input too.
  WriteText(dir + "/broken.yaml",
            "name: x\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: hold, duration: 0.5, ramp: 0.1}\n");
  std::filesystem::create_directories(dir + "/baselines");
  WriteText(dir + "/baselines/x.json", "{\"metrics\": 3}");
  r = RunExotwin("regress --suite " + dir + " --out " + dir + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("x.json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace exotwin::testing
