// Real-time execution for a hardware-in-the-loop stand-in (`exotwin serve --clock realtime`): the
// process's memory locked (no page fault in the loop) and a SCHED_FIFO priority, when the caller asks
// and the kernel allows; and the wait for an absolute deadline of CLOCK_MONOTONIC.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// Monotonic wall-clock time (s, CLOCK_MONOTONIC): the links' time stamps and the real-time clock.
double MonotonicSeconds();

// What RequestRealtime obtained.
struct RealtimeGrant {
  bool memory_locked = false;  // mlockall(MCL_CURRENT | MCL_FUTURE) succeeded
  bool fifo = false;           // SCHED_FIFO at `priority` taken
  int priority = 0;            // the priority asked for (0: none asked)
  std::string refused;         // what the kernel refused and why ("" when all was granted)
};

// Locks the memory and takes SCHED_FIFO `priority` (1..99) for the calling process. A refusal (no
// CAP_SYS_NICE / RLIMIT_RTPRIO below `priority`, RLIMIT_MEMLOCK too small) is not an error: the grant
// says what was refused, the caller warns and runs on. Throws InputError when priority is outside 1..99.
RealtimeGrant RequestRealtime(int priority);

// Puts the calling thread at normal priority (SCHED_OTHER, nice unchanged) when it runs at a real-time
// one (inherited from the thread that started it): for background threads of a real-time process (a
// log writer) that must not hold the CPU from its tick. Lowering a priority is always allowed.
void DropRealtimePriority();

// Sleeps until `deadline_s` (MonotonicSeconds) minus
// `spin_s`, then spins until the deadline (the sleep's wake-up latency taken off the tick's start);
// returns the time reached (>= deadline_s; later when the deadline had already passed).
double WaitUntil(double deadline_s, double spin_s);

// The machine's floor for a tick loop (`exotwin bench`'s row beside the twin's real-time runs, as
// rt-tests' cyclictest): ticks on the absolute deadlines t0 + k period_s for duration_s, each waited
// for as the twin's (WaitUntil with spin_s), with no work in between; returns each tick's start minus
// its deadline (s), in tick order. Runs at the calling thread's priority.
std::vector<double> DeadlineLoopJitter(double period_s, double duration_s, double spin_s);

}  // namespace exotwin
