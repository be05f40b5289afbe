#include "batch/fork_pool.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <stdexcept>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace exotwin {
namespace {

using Clock = std::chrono::steady_clock;

// What a worker sends back after each job: the job's index, its exit code, and whether the worker
// takes another job (0 after an exception: it exits, and no job may be handed to it).
struct Report {
  uint64_t index;
  int64_t code;
  uint64_t alive;
};

int g_worker_slot = -1;  // ForkWorkerSlot

struct Worker {
  pid_t pid = -1;
  int slot = 0;            // ForkWorkerSlot in the worker
  int to = -1, from = -1;  // parent's ends: job indices to the worker, reports from it
  long job = -1;           // the job it runs, -1 idle
  Clock::time_point started;
};

// Reads or writes exactly n bytes; false on end of file or error (EINTR retried).
bool ReadAll(int fd, void* p, size_t n) {
  auto* b = static_cast<char*>(p);
  while (n > 0) {
    const ssize_t r = read(fd, b, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    b += r, n -= static_cast<size_t>(r);
  }
  return true;
}
bool WriteAll(int fd, const void* p, size_t n) {
  const auto* b = static_cast<const char*>(p);
  while (n > 0) {
    const ssize_t w = write(fd, b, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    b += w, n -= static_cast<size_t>(w);
  }
  return true;
}

// The worker's life: job indices in, reports out, until the parent closes the pipe. An exception
// escaping a job reports 70 and ends the worker (its state may be broken).
[[noreturn]] void WorkerMain(int in, int out, const std::function<int(size_t)>& job) {
  uint64_t index = 0;
  while (ReadAll(in, &index, sizeof index)) {
    int code = 70;
    bool healthy = true;
    try {
      code = job(static_cast<size_t>(index));
    } catch (...) {
      code = 70;
      healthy = false;
    }
    std::fflush(stdout);
    std::fflush(stderr);
    const Report r{index, code & 0xff, healthy ? 1u : 0u};
    if (!WriteAll(out, &r, sizeof r) || !healthy) _exit(healthy ? 0 : 70);
  }
  _exit(0);
}

}  // namespace

int ForkWorkerSlot() { return g_worker_slot; }

int DefaultWorkers() {
  const unsigned n = std::thread::hardware_concurrency();
  return n > 0 ? static_cast<int>(n) : 1;
}

std::vector<JobOutcome> RunForked(size_t n, int workers, const std::function<int(size_t)>& job,
                                  const std::function<void(size_t, const JobOutcome&)>& on_done) {
  if (workers < 1) workers = 1;
  std::vector<JobOutcome> out(n);
  std::deque<size_t> todo;
  for (size_t i = 0; i < n; ++i) todo.push_back(i);
  std::vector<Worker> pool;
  size_t finished = 0;
  // A worker that died is reaped; the job it ran (if any) ends with its exit code or signal.
  auto finish = [&](size_t i, const JobOutcome& o) {
    out[i] = o;
    ++finished;
    if (on_done) on_done(i, o);
  };
  auto retire = [&](size_t w) {
    Worker& k = pool[w];
    close(k.to);
    close(k.from);
    int status = 0;
    while (waitpid(k.pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (k.job >= 0) {
      JobOutcome o;
      o.wall_s = std::chrono::duration<double>(Clock::now() - k.started).count();
      if (WIFEXITED(status)) o.exit_code = WEXITSTATUS(status);
      else if (WIFSIGNALED(status)) o.signal = WTERMSIG(status);
      finish(static_cast<size_t>(k.job), o);
    }
    pool.erase(pool.begin() + static_cast<long>(w));
  };
  auto spawn = [&]() -> bool {
    int down[2], up[2];
    if (pipe2(down, O_CLOEXEC) != 0) return false;
    if (pipe2(up, O_CLOEXEC) != 0) {
      close(down[0]), close(down[1]);
      return false;
    }
    std::fflush(stdout);
    std::fflush(stderr);
    int slot = 0;  // the lowest slot no live worker holds
    while (std::any_of(pool.begin(), pool.end(), [&](const Worker& k) { return k.slot == slot; })) ++slot;
    const pid_t pid = fork();
    if (pid < 0) {
      close(down[0]), close(down[1]), close(up[0]), close(up[1]);
      return false;
    }
    if (pid == 0) {
      g_worker_slot = slot;
      std::signal(SIGPIPE, SIG_DFL);
      for (const Worker& k : pool) close(k.to), close(k.from);
      close(down[1]);
      close(up[0]);
      WorkerMain(down[0], up[1], job);
    }
    close(down[0]);
    close(up[1]);
    Worker k;
    k.pid = pid;
    k.slot = slot;
    k.to = down[1];
    k.from = up[0];
    pool.push_back(k);
    return true;
  };
  // A dead worker's pipe must not kill the parent with SIGPIPE: a failed write retires the worker.
  const auto old_sigpipe = std::signal(SIGPIPE, SIG_IGN);
  try {
    while (finished < n) {
      while (!todo.empty() && pool.size() < std::min(static_cast<size_t>(workers), n - finished))
        if (!spawn()) {
          if (pool.empty()) throw std::runtime_error("fork failed");
          break;  // out of processes: go on with the workers there are
        }
      for (size_t w = 0; w < pool.size() && !todo.empty();) {
        if (pool[w].job >= 0) {
          ++w;
          continue;
        }
        const uint64_t index = todo.front();
        pool[w].job = static_cast<long>(index);
        pool[w].started = Clock::now();
        if (WriteAll(pool[w].to, &index, sizeof index)) {
          todo.pop_front();
          ++w;
        } else {  // it died idle: the job goes to another worker
          pool[w].job = -1;
          retire(w);
        }
      }
      std::vector<pollfd> fds;
      for (const Worker& k : pool) fds.push_back({k.from, POLLIN, 0});
      if (fds.empty()) continue;
      if (poll(fds.data(), fds.size(), -1) < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error("poll failed");
      }
      for (size_t w = fds.size(); w-- > 0;) {
        if (!fds[w].revents) continue;
        Report r{};
        if (ReadAll(pool[w].from, &r, sizeof r) && static_cast<long>(r.index) == pool[w].job) {
          JobOutcome o;
          o.exit_code = static_cast<int>(r.code);
          o.wall_s = std::chrono::duration<double>(Clock::now() - pool[w].started).count();
          pool[w].job = -1;
          finish(static_cast<size_t>(r.index), o);
          if (!r.alive) retire(w);  // it exits after this report: reaped before it is handed a job
        } else {
          retire(w);  // ended (crash, exit() in a job, or after an exception): reaped
        }
      }
    }
    while (!pool.empty()) retire(pool.size() - 1);  // EOF on their pipes: they exit 0
  } catch (...) {
    std::signal(SIGPIPE, old_sigpipe);
    throw;
  }
  std::signal(SIGPIPE, old_sigpipe);
  return out;
}

}  // namespace exotwin
