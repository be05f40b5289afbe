// Nothing lost: a run killed in the middle (SIGKILL) leaves a measured.csv that reads back as a valid
// measured-data CSV (whole lines only) with the rows written so far, and no result.json (written
// atomically at the end).
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include "analysis/measured_data.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

TEST(AbortKeepsLog, KilledRunLeavesReadableLog) {
  const std::string dir = testing::TempDir("abort");
  const std::string bin = testing::ExotwinBin();
  const std::string scenario = std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execl(bin.c_str(), bin.c_str(), "run", scenario.c_str(), "--out", dir.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
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

}  // namespace
}  // namespace exotwin
