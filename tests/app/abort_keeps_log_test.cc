// Nothing lost: a run killed in the middle (SIGKILL) leaves a measured.csv that reads back as a valid
// measured-data CSV (whole lines only) with the rows written so far, and no result.json (written
// atomically at the end). A check naming a metric the run does not produce exits 2 only after
// result.json holds the run's metrics.
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <filesystem>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "formats/measured_data.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

TEST(AbortKeepsLog, KilledRunLeavesReadableLog) {
  const testing::ScopedTempDir tmp("abort");
  const std::string dir = tmp.path();
  const std::string scenario = std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml";
  const pid_t pid = testing::StartExotwin({"run", scenario, "--out", dir});
  ASSERT_GE(pid, 0);
  // Wait until some rows are on disk, then kill without warning.
  const std::string log = dir + "/measured.csv";
  for (int i = 0; i < 2000; ++i) {  // up to 20 s (slow under sanitizers)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::error_code ec;
    if (std::filesystem::exists(log) && std::filesystem::file_size(log, ec) > 200000) break;
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it could be killed";
  const MeasuredData d = ReadMeasuredCsv(log);  // throws on a partial line
  EXPECT_GT(d.size(), 1000u);
  EXPECT_LT(d.size(), 60000u);
  EXPECT_FALSE(std::filesystem::exists(dir + "/result.json"));
}

// A check naming a metric the run does not report is refused when the scenario is read (issue 43:
// runner/scenario_metrics.h), before the run: no run spent, nothing written.
TEST(AbortKeepsLog, UnknownCheckMetricIsRefusedBeforeTheRun) {
  const testing::ScopedTempDir tmp("unknown_metric");
  const std::string dir = tmp.path();
  const std::string yaml = dir + "/s.yaml";
  std::ofstream(yaml) << "name: short\nseed: 1\ndevice: exowheel\nsubject: {preset: S1}\n"
                         "protocol: {trajectory: gait, stride_period: 2.0, duration: 1.0, ramp: 0.5}\n"
                         "checks:\n  - {name: typo, metric: tracking_rms_hip_dge, max: 1}\n";
  const testing::RunResult r = testing::RunExotwin("run " + yaml + " --out " + dir + "/out");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(yaml + ": checks[0].metric: unknown metric 'tracking_rms_hip_dge' for an EXOwheel scenario"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out")) << "refused before the run: nothing written";
}

}  // namespace
}  // namespace exotwin
