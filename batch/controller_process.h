// A scenario run with its controller in another process: the twin of `exotwin serve` and
// the deployable controller (exotwin-controller) on a private shared-memory link, in lockstep, so the result is
// the in-process run's (the regression gate's `regress --controller-process`).
#pragma once
#include <cstdint>
#include <string>

#include "protocol/bus_address.h"
#include "runner/remote_controller.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {

// Writes DIR/controller.yaml, the controller file of the scenario run with seed `seed`: EXOwheel
// plain trials ControllerFileOf (the subject resolved as the run does), HAL-3 the loop of its first run
// (HalControllerFileOf); returns its path. An emg_calibration scenario has none (its trials run
// different controller files: its controller is started on the scenario file): returns "". Throws
// InputError if it cannot be written.
std::string WriteControllerFile(const Scenario& s, const std::string& dir, uint64_t seed);

// Writes `path`: the scenario's device and controller part, what exotwin-controller started on a
// scenario reads (the rest it asks the twin for); returns `path`. Throws InputError if it cannot be written.
std::string WriteControllerScenario(const Scenario& s, const std::string& path);

// The exotwin-controller executable: next to the running executable, else in ../deploy/ of its folder
// (the build tree). Empty when neither exists.
std::string DefaultControllerBinary();

// Runs `s` as RunScenario does (any device and protocol), the controller being `controller_bin` started
// on the scenario's device and controller part (WriteControllerScenario: it downloads each run's
// controller file from the twin) on a private link (its log in opt.out_dir/controller.log) and
// stopped at the end (NMT stop; killed if still there 5 s later), in lockstep (or `clock`). The link is
// `transport`: kShm (a private segment, shm:exotwin_link_XXXXXX) or kUnix (sockets in a private
// folder). Its waits spin kDefaultLinkSpin before they block, on both ends; over kUnix only when this
// process may run on more than one CPU (the controller inherits its affinity: both ends then block at
// once), over kShm always (on one CPU the spin yields it). The run fails (a check result
// "controller_link" failed) when the controller was lost. Throws InputError when the link cannot be set up.
RunResult RunWithControllerProcess(const Scenario& s, RunOptions opt, const std::string& controller_bin,
                                   double timeout_s = 10.0, ServeClock clock = ServeClock::kLockstep,
                                   BusKind transport = BusKind::kShm);

}  // namespace exotwin
