// A pool of forked worker processes: `workers` long-lived children, forked once (after the parent
// loaded and parsed what the jobs share, which they inherit), each taking the next job index from the
// parent through a pipe and reporting its exit code back, so the parent's share of a sweep is a few
// pipe messages per job instead of a fork. Process isolation makes any library state (MuJoCo's XML
// parser, stdio) safe to use from every job, and a crash takes down one worker and its job, not the
// sweep: the job is recorded with the worker's exit code or signal and a new worker takes the rest.
// The parent stays single-threaded.
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

namespace exotwin {

struct JobOutcome {
  int exit_code = -1;  // the job function's return value (or its process's exit code), -1 if killed
  int signal = 0;      // the signal that killed the job's process, 0 if it exited
  double wall_s = 0;   // s, from handing the job to a worker to its report (or the worker's end)
};

// Runs job(i) for i in [0, n) in at most `workers` (>= 1) child processes, started in index order.
// job's return value (0..255) is the job's exit code; an exception escaping job gives 70 (and ends that
// worker); a job that ends its process (exit, signal) gives the process's exit code or signal.
// on_done(i, outcome) runs in the parent after each job ends (completion order; may be empty).
// Flushes stdout/stderr before every fork and after every job. Returns the outcomes by index.
std::vector<JobOutcome> RunForked(size_t n, int workers, const std::function<int(size_t)>& job,
                                  const std::function<void(size_t, const JobOutcome&)>& on_done = {});

// In a worker of RunForked: its slot, 0..workers-1, unique among the live workers (a worker that
// replaces a dead one takes its slot), e.g. to give each worker its own CPU. -1 outside a worker.
int ForkWorkerSlot();

// Default worker count: std::thread::hardware_concurrency(), at least 1.
int DefaultWorkers();

}  // namespace exotwin
