// A pool of forked worker processes: each job runs in its own child process, at most `workers` at a
// time. Process isolation makes any library state (MuJoCo's XML parser, stdio) safe to use from
// every job, and a crash takes down one job, not the sweep. The parent stays single-threaded.
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

namespace exotwin {

struct JobOutcome {
  int exit_code = -1;  // the child's exit code (the job function's return value), -1 if killed
  int signal = 0;      // the signal that killed the child, 0 if it exited
  double wall_s = 0;   // s, from fork to reaping
};

// Runs job(i) for i in [0, n) in child processes, at most `workers` (>= 1) at once, in index order.
// job's return value (0..255) is the child's exit code; an exception escaping job exits with 70.
// on_done(i, outcome) runs in the parent after each job ends (completion order; may be empty).
// Flushes stdout/stderr before every fork. Returns the outcomes by index.
std::vector<JobOutcome> RunForked(size_t n, int workers, const std::function<int(size_t)>& job,
                                  const std::function<void(size_t, const JobOutcome&)>& on_done = {});

// Default worker count: std::thread::hardware_concurrency(), at least 1.
int DefaultWorkers();

}  // namespace exotwin
