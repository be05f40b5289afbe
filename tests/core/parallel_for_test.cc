// Tests of core/parallel_for.h: every item once on any thread count, results by index the same bits,
// the first exception rethrown after all items ran, a nested call serial.
#include "core/parallel_for.h"

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace exotwin {
namespace {

TEST(ParallelFor, EveryItemOnceAndTheSameResultOnAnyThreadCount) {
  constexpr size_t kN = 1000;
  std::vector<double> serial(kN);
  for (size_t i = 0; i < kN; ++i) serial[i] = std::sin(0.001 * static_cast<double>(i * i));
  for (int threads : {0, 1, 2, 3, 8}) {
    std::vector<double> out(kN, std::nan(""));
    std::vector<std::atomic<int>> hits(kN);
    ParallelFor(kN, threads, [&](size_t i) {
      hits[i].fetch_add(1);
      out[i] = std::sin(0.001 * static_cast<double>(i * i));
    });
    for (size_t i = 0; i < kN; ++i) EXPECT_EQ(hits[i].load(), 1) << "threads " << threads << " item " << i;
    EXPECT_EQ(out, serial) << "threads " << threads;
  }
  ParallelFor(0, 2, [](size_t) { FAIL() << "no item to run"; });
}

TEST(ParallelFor, TheFirstExceptionIsRethrownAfterEveryItemRan) {
  std::atomic<int> ran{0};
  EXPECT_THROW(ParallelFor(50, 2,
                           [&](size_t i) {
                             ran.fetch_add(1);
                             if (i % 10 == 3) throw std::runtime_error("item " + std::to_string(i));
                           }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 50);
}

TEST(ParallelFor, ANestedCallRunsOnTheWorkersThread) {
  std::vector<std::thread::id> outer(4), inner(4 * 3);
  ParallelFor(4, 2, [&](size_t i) {
    outer[i] = std::this_thread::get_id();
    ParallelFor(3, 2, [&](size_t k) { inner[3 * i + k] = std::this_thread::get_id(); });
  });
  for (size_t i = 0; i < 4; ++i)
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(inner[3 * i + k], outer[i]);
}

// ParallelForRanges: contiguous ranges covering [0, n) once, as many as the threads asked for, one
// for a loop shorter than kMinSamplesToSplit.
TEST(ParallelFor, RangesCoverTheSamplesOnceInContiguousPieces) {
  for (size_t n : {size_t{0}, size_t{7}, kMinSamplesToSplit - 1, kMinSamplesToSplit, size_t{100003}}) {
    for (int threads : {1, 2, 3}) {
      std::vector<int> hits(n, 0);
      std::atomic<int> ranges{0};
      ParallelForRanges(n, threads, [&](size_t begin, size_t end) {
        ranges.fetch_add(1);
        for (size_t i = begin; i < end; ++i) ++hits[i];
      });
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i], 1) << "n " << n << " threads " << threads << " i " << i;
      EXPECT_EQ(ranges.load(), n < kMinSamplesToSplit ? 1 : threads) << "n " << n;
    }
  }
}

}  // namespace
}  // namespace exotwin
