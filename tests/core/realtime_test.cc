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

TEST(Realtime, PriorityOutsideOneTo99IsAnInputError) {
  EXPECT_THROW(RequestRealtime(0), InputError);
  EXPECT_THROW(RequestRealtime(100), InputError);
}

}  // namespace
}  // namespace exotwin
