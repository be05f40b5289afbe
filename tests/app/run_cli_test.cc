// `exotwin run --out` (issue 21): an --out naming a file exits 2 naming it; a second run on a folder
// that a running exotwin holds refuses (exit 2) and names the holder; a lock left by a killed run
// does not block (flock(2) is released by the kernel when the holder dies).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include "runner/out_folder_lock.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

std::string Scenario(double duration) {
  return "name: out_lock\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: hold, duration: " +
         std::to_string(duration) + ", ramp: 0}\n";
}

TEST(RunCli, OutNamingAFileExitsTwoNamingIt) {
  const testing::ScopedTempDir dir_tmp("run_out_file");
  const std::string dir = dir_tmp.path();
  WriteText(dir + "/s.yaml", Scenario(0.05));
  WriteText(dir + "/taken", "not a folder\n");
  const auto r = RunExotwin("run " + dir + "/s.yaml --out " + dir + "/taken");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("exotwin: error: --out " + dir + "/taken: exists and is not a folder"), std::string::npos)
      << r.output;
  EXPECT_EQ(testing::ReadText(dir + "/taken"), "not a folder\n");
}

TEST(RunCli, SecondRunOnAHeldOutRefusesAndAKilledRunsLockDoesNotBlock) {
  const testing::ScopedTempDir dir_tmp("run_out_lock");
  const std::string dir = dir_tmp.path();
  const std::string out = dir + "/out", lock = out + "/" + kOutFolderLockName;
  WriteText(dir + "/long.yaml", Scenario(3600));
  WriteText(dir + "/short.yaml", Scenario(0.05));
  const std::string bin = testing::ExotwinBin(), long_yaml = dir + "/long.yaml";
  const pid_t first = fork();
  ASSERT_GE(first, 0);
  if (first == 0) {
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execl(bin.c_str(), bin.c_str(), "run", long_yaml.c_str(), "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // The first run holds the folder once its pid is in the lock file.
  const std::string pid_line = std::to_string(first) + "\n";
  for (int i = 0; i < 6000 && testing::ReadText(lock) != pid_line; ++i)  // up to 60 s (sanitizers)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(testing::ReadText(lock), pid_line);

  const auto second = RunExotwin("run " + dir + "/short.yaml --out " + out);
  EXPECT_EQ(second.exit_code, 2) << second.output;
  EXPECT_NE(second.output.find("--out " + out + ": another exotwin run (pid " + std::to_string(first) + ")"),
            std::string::npos)
      << second.output;
  EXPECT_FALSE(std::filesystem::exists(out + "/result.json"));

  kill(first, SIGKILL);
  int status = 0;
  waitpid(first, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the first run ended before it was killed";
  ASSERT_EQ(testing::ReadText(lock), pid_line);  // the killed run's lock file stays behind

  const auto third = RunExotwin("run " + dir + "/short.yaml --out " + out);
  EXPECT_EQ(third.exit_code, 0) << third.output;
  EXPECT_TRUE(std::filesystem::exists(out + "/result.json"));
}

}  // namespace
}  // namespace exotwin
