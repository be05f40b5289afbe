// A stop request from outside the process: SIGINT or SIGTERM received while a scenario runs.
//
// InstallStopSignalHandlers() is called by the commands that run scenarios in the foreground
// (`exotwin run`, `exotwin render`), not globally: regress/sweep workers keep the default action (the
// parent handles its children). The handler is async-signal-safe: it stores the signal number in a
// volatile sig_atomic_t and restores the default action of both signals, so a second SIGINT or
// SIGTERM while the run is stopping terminates the process (a stuck run can still be killed).
// The co-simulation rig polls StopSignal() once per physics step (runner/cosim_rig.h).
#pragma once

namespace exotwin {

// Installs the handler for SIGINT and SIGTERM (SA_RESTART: interrupted system calls resume).
void InstallStopSignalHandlers();

// The signal number of the first stop request received (SIGINT = 2, SIGTERM = 15), 0 if none.
int StopSignal();

// Clears the stop request (tests). The handlers are not reinstalled.
void ResetStopSignal();

// "SIGINT", "SIGTERM", or "signal" for another number (static strings).
const char* StopSignalName(int sig);

}  // namespace exotwin
