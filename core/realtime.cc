#include "core/realtime.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>

#include "core/error.h"

namespace exotwin {
double MonotonicSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

RealtimeGrant RequestRealtime(int priority) {
  if (priority < 1 || priority > 99)
    throw InputError("--rt-priority: expected a SCHED_FIFO priority 1..99, got " + std::to_string(priority));
  RealtimeGrant g;
  g.priority = priority;
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) g.memory_locked = true;
  else g.refused = std::string("mlockall: ") + std::strerror(errno) + " (RLIMIT_MEMLOCK too small?)";
  sched_param p{};
  p.sched_priority = priority;
  if (::sched_setscheduler(0, SCHED_FIFO, &p) == 0) {
    g.fifo = true;
  } else {
    const int err = errno;
    rlimit rl{};
    ::getrlimit(RLIMIT_RTPRIO, &rl);
    if (!g.refused.empty()) g.refused += "; ";
    g.refused += "SCHED_FIFO " + std::to_string(priority) + ": " + std::strerror(err) +
                 " (needs CAP_SYS_NICE or RLIMIT_RTPRIO >= " + std::to_string(priority) + ", which is " +
                 (rl.rlim_cur == RLIM_INFINITY ? std::string("unlimited") : std::to_string(rl.rlim_cur)) + ")";
  }
  return g;
}

void DropRealtimePriority() {
  int policy = 0;
  sched_param p{};
  if (::pthread_getschedparam(::pthread_self(), &policy, &p) != 0 || (policy != SCHED_FIFO && policy != SCHED_RR)) return;
  p.sched_priority = 0;
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &p);
}

double WaitUntil(double deadline_s, double spin_s) {
  const double wake = deadline_s - spin_s;
  double now = MonotonicSeconds();
  if (now < wake) {
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(std::floor(wake));
    ts.tv_nsec = std::min(999999999L, static_cast<long>((wake - std::floor(wake)) * 1e9));
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
  }
  while ((now = MonotonicSeconds()) < deadline_s) {
  }
  return now;
}

std::vector<double> DeadlineLoopJitter(double period_s, double duration_s, double spin_s) {
  const long ticks = std::lround(duration_s / period_s);
  std::vector<double> jitter;
  jitter.reserve(static_cast<size_t>(std::max(0L, ticks)));  // no allocation in the loop
  const double t0 = MonotonicSeconds() + period_s;
  for (long k = 0; k < ticks; ++k) {
    const double due = t0 + static_cast<double>(k) * period_s;
    jitter.push_back(WaitUntil(due, spin_s) - due);
  }
  return jitter;
}

}  // namespace exotwin
