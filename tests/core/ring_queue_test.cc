// RingQueue (core/ring_queue.h): FIFO order across wrap-around and growth, storage kept by clear().
#include "core/ring_queue.h"

#include <gtest/gtest.h>

#include <deque>
#include <random>

namespace exotwin {
namespace {

TEST(RingQueue, BehavesAsADequeFifoUnderRandomPushesAndPops) {
  RingQueue<int> q;
  std::deque<int> ref;
  std::mt19937 gen(3);
  for (int k = 0; k < 20000; ++k) {
    if (ref.empty() || gen() % 3 != 0) {
      q.push_back(k);
      ref.push_back(k);
    } else {
      ASSERT_EQ(q.front(), ref.front());
      q.pop_front();
      ref.pop_front();
    }
    ASSERT_EQ(q.size(), ref.size());
    if (!ref.empty()) {
      ASSERT_EQ(q.back(), ref.back());
      const size_t i = gen() % ref.size();
      ASSERT_EQ(q[i], ref[i]);
    }
  }
}

TEST(RingQueue, ClearEmptiesAndTheQueueIsReusable) {
  RingQueue<double> q;
  for (int i = 0; i < 40; ++i) q.push_back(i);
  q.clear();
  EXPECT_TRUE(q.empty());
  q.push_back(7.5);
  EXPECT_EQ(q.size(), 1u);
  EXPECT_EQ(q.front(), 7.5);
}

}  // namespace
}  // namespace exotwin
