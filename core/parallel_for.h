// ParallelFor: independent work items on a few std::threads, for the offline analyses (diagnose's
// replays and rollouts). Not for the real-time path.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace exotwin {

namespace parallel_for_detail {
inline thread_local bool in_worker = false;  // inside ParallelFor's work: nested calls run serially
}  // namespace parallel_for_detail

// The machine's cores (std::thread::hardware_concurrency, at least 1): the offline analyses' default
// thread count.
inline int MachineCores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

// True inside a ParallelFor item (where a nested ParallelFor runs serially).
inline bool InsideParallelFor() { return parallel_for_detail::in_worker; }

// Runs f(0) .. f(n - 1) on up to `threads` std::threads (the calling thread among them), each item once,
// in no set order: f must write only what item i owns (results stored by index do not depend on the
// thread count). A nested call from inside an item runs serially. The first exception is rethrown after
// all have finished.
template <class F>
void ParallelFor(size_t n, int threads, F f) {
  using parallel_for_detail::in_worker;
  if (in_worker) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    in_worker = true;
    for (size_t i; (i = next.fetch_add(1)) < n;) {
      try {
        f(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
    in_worker = false;
  };
  const size_t T = std::min(n, static_cast<size_t>(std::max(1, threads)));
  std::vector<std::thread> pool;
  for (size_t k = 1; k < T; ++k) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

// A loop over a record's samples shorter than this runs on the calling thread: a thread costs more
// than it saves there.
constexpr size_t kMinSamplesToSplit = 20000;

// f(begin, end) over [0, n) cut into contiguous ranges, one per thread: `threads` of them, one when
// n < kMinSamplesToSplit. For per-sample loops whose item i writes only its own values (the same bits on
// any thread count).
template <class F>
void ParallelForRanges(size_t n, int threads, F f) {
  const size_t T = n < kMinSamplesToSplit ? 1 : static_cast<size_t>(std::max(1, threads));
  ParallelFor(T, static_cast<int>(T), [&](size_t k) { f(k * n / T, (k + 1) * n / T); });
}

}  // namespace exotwin
