#include "runner/fork_pool.h"

#include <chrono>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace exotwin {

int DefaultWorkers() {
  const unsigned n = std::thread::hardware_concurrency();
  return n > 0 ? static_cast<int>(n) : 1;
}

std::vector<JobOutcome> RunForked(size_t n, int workers, const std::function<int(size_t)>& job,
                                  const std::function<void(size_t, const JobOutcome&)>& on_done) {
  using Clock = std::chrono::steady_clock;
  if (workers < 1) workers = 1;
  std::vector<JobOutcome> out(n);
  std::map<pid_t, std::pair<size_t, Clock::time_point>> running;
  size_t next = 0;
  while (next < n || !running.empty()) {
    while (next < n && running.size() < static_cast<size_t>(workers)) {
      std::fflush(stdout);
      std::fflush(stderr);
      const pid_t pid = fork();
      if (pid < 0) {
        if (running.empty()) throw std::runtime_error("fork failed");
        break;  // out of processes: wait for one to finish
      }
      if (pid == 0) {
        int code = 70;
        try {
          code = job(next);
        } catch (...) {
          code = 70;
        }
        std::fflush(stdout);
        std::fflush(stderr);
        _exit(code & 0xff);
      }
      running[pid] = {next, Clock::now()};
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("waitpid failed");
    auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    JobOutcome& o = out[it->second.first];
    o.wall_s = std::chrono::duration<double>(Clock::now() - it->second.second).count();
    if (WIFEXITED(status)) o.exit_code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status)) o.signal = WTERMSIG(status);
    const size_t index = it->second.first;
    running.erase(it);
    if (on_done) on_done(index, o);
  }
  return out;
}

}  // namespace exotwin
