// The stop request of SIGINT / SIGTERM: see stop_signal.h.
#include "core/stop_signal.h"

#include <csignal>

namespace exotwin {
namespace {

volatile std::sig_atomic_t g_stop = 0;

void SetDefault(int sig) {
  struct sigaction sa {};
  sa.sa_handler = SIG_DFL;
  sigemptyset(&sa.sa_mask);
  sigaction(sig, &sa, nullptr);
}

// Async-signal-safe: one store and sigaction (POSIX.1 async-signal-safe list).
void OnStopSignal(int sig) {
  if (g_stop == 0) g_stop = sig;
  SetDefault(SIGINT);
  SetDefault(SIGTERM);
}

}  // namespace

void InstallStopSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);  // the other stop signal waits until the handler returns
  sigaddset(&sa.sa_mask, SIGTERM);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int StopSignal() { return g_stop; }

void ResetStopSignal() { g_stop = 0; }

const char* StopSignalName(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "signal";
  }
}

}  // namespace exotwin
