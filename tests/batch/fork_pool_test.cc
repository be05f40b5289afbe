// RunForked (batch/fork_pool.h): exit codes by index, a crashing job recorded with its signal while
// the other jobs go on, exceptions as 70, jobs sharing a few long-lived workers, each in its slot.
#include "batch/fork_pool.h"

#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "tests/temp_dir.h"

namespace exotwin {
namespace {

TEST(RunForked, ReturnsEachJobsCodeByIndexAndCallsOnDoneOnce) {
  std::set<size_t> done;
  const auto out = RunForked(
      12, 3, [](size_t i) { return static_cast<int>(i % 4); },
      [&](size_t i, const JobOutcome& o) {
        EXPECT_TRUE(done.insert(i).second);
        EXPECT_EQ(o.exit_code, static_cast<int>(i % 4));
      });
  ASSERT_EQ(out.size(), 12u);
  EXPECT_EQ(done.size(), 12u);
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].exit_code, static_cast<int>(i % 4));
    EXPECT_EQ(out[i].signal, 0);
  }
}

TEST(RunForked, ACrashOrAnExceptionEndsOnlyItsJob) {
  const auto out = RunForked(8, 2, [](size_t i) -> int {
    if (i == 2) std::raise(SIGKILL);
    if (i == 4) throw std::runtime_error("boom");
    if (i == 6) _exit(9);
    return 0;
  });
  for (size_t i = 0; i < out.size(); ++i) {
    if (i == 2) {
      EXPECT_EQ(out[i].signal, SIGKILL);
      EXPECT_EQ(out[i].exit_code, -1);
    } else {
      EXPECT_EQ(out[i].signal, 0) << i;
      EXPECT_EQ(out[i].exit_code, i == 4 ? 70 : i == 6 ? 9 : 0) << i;
    }
  }
}

// A worker that reported an exception exits: the next job goes to a fresh worker, never to it (one
// worker makes the hand-over immediate: the job after the exception would otherwise end with 70).
TEST(RunForked, NoJobIsHandedToAWorkerThatExitsAfterAnException) {
  const auto out = RunForked(4, 1, [](size_t i) -> int {
    if (i == 0) throw std::runtime_error("boom");
    return 0;
  });
  EXPECT_EQ(out[0].exit_code, 70);
  for (size_t i = 1; i < out.size(); ++i) {
    EXPECT_EQ(out[i].exit_code, 0) << i;
    EXPECT_EQ(out[i].signal, 0) << i;
  }
}

TEST(RunForked, JobsShareLongLivedWorkers) {  // the parent forks `workers` processes, not one per job
  const testing::ScopedTempDir tmp("fork_pool");
  const std::string dir = tmp.path();
  RunForked(10, 2, [&](size_t i) {
    std::ofstream(dir + "/" + std::to_string(i)) << getpid();
    return 0;
  });
  std::set<std::string> pids;
  for (int i = 0; i < 10; ++i) {
    std::ifstream f(dir + "/" + std::to_string(i));
    std::string pid;
    f >> pid;
    pids.insert(pid);
  }
  EXPECT_LE(pids.size(), 2u);
}

// ForkWorkerSlot: 0..workers-1 in a worker (a worker replacing a dead one takes its slot), -1 outside.
TEST(RunForked, EachWorkerHasASlotBelowTheWorkerCount) {
  EXPECT_EQ(ForkWorkerSlot(), -1);
  const auto out = RunForked(12, 3, [](size_t i) {
    if (i == 4) std::raise(SIGKILL);  // its worker dies: the next one takes its slot
    return ForkWorkerSlot();
  });
  std::set<int> slots;
  for (size_t i = 0; i < out.size(); ++i) {
    if (i == 4) continue;
    EXPECT_GE(out[i].exit_code, 0) << i;
    EXPECT_LT(out[i].exit_code, 3) << i;
    slots.insert(out[i].exit_code);
  }
  EXPECT_GE(slots.size(), 1u);
  EXPECT_EQ(out[4].signal, SIGKILL);
  EXPECT_EQ(ForkWorkerSlot(), -1);
}

TEST(RunForked, NoJobsNoWorkers) { EXPECT_TRUE(RunForked(0, 4, [](size_t) { return 0; }).empty()); }

}  // namespace
}  // namespace exotwin
