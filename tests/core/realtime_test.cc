// core/realtime.h: the wait for an absolute deadline of the monotonic clock, and the real-time request's
// range check (a refusal by the kernel is not an error: the grant says what was refused).
#include "core/realtime.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace exotwin {
namespace {

TEST(Realtime, WaitUntilReachesTheDeadlineAndNotEarlier) {
  for (const double spin : {0.0, 200e-6}) {
    const double deadline = MonotonicSeconds() + 2e-3;
    const double reached = WaitUntil(deadline, spin);
    EXPECT_GE(reached, deadline);
    EXPECT_GE(MonotonicSeconds(), deadline);
  }
  const double before = MonotonicSeconds();  // a deadline passed: returns at once, the time reached
  const double reached = WaitUntil(before - 1.0, 100e-6);
  EXPECT_GE(reached, before);
  EXPECT_LT(reached - before, 0.1);
}

// The floor loop: one figure per tick of the duration, none before its deadline; ticks on absolute
// deadlines, so the loop's own time does not add up (a 50-tick loop takes 50 periods, not more).
TEST(Realtime, DeadlineLoopJitterOneTickPerPeriodNoneEarly) {
  const double t0 = MonotonicSeconds();
  const std::vector<double> j = DeadlineLoopJitter(1e-3, 0.05, 100e-6);
  const double took = MonotonicSeconds() - t0;
  ASSERT_EQ(j.size(), 50u);
  for (const double x : j) EXPECT_GE(x, 0.0);
  EXPECT_GE(took, 0.05);
  EXPECT_LT(took, 0.05 + 1e-3 + j.back() + 0.01);  // the last tick's lateness and the set-up, no drift
}

TEST(Realtime, PriorityOutsideOneTo99IsAnInputError) {
  EXPECT_THROW(RequestRealtime(0), InputError);
  EXPECT_THROW(RequestRealtime(100), InputError);
}

}  // namespace
}  // namespace exotwin
