// A scenario run with its controller in another process (issue 17): the twin of `exotwin serve` and
// the deployable controller (exotwin-controller) on a private Unix link, in lockstep, so the result is
// the in-process run's (the regression gate's `regress --controller-process`).
#pragma once
#include <string>

#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {

// True when the scenario can run with a remote controller: EXOwheel devices with plain trials (not
// hal3, not an emg_calibration protocol).
bool ServesScenario(const Scenario& s);

// Writes DIR/controller.yaml, the controller file of the scenario (ControllerFileOf with the subject
// resolved as the run does), and returns its path. Throws InputError if it cannot be written.
std::string WriteControllerFile(const Scenario& s, const std::string& dir);

// The exotwin-controller executable: next to the running executable, else in ../deploy/ of its folder
// (the build tree). Empty when neither exists.
std::string DefaultControllerBinary();

// Runs `s` as RunScenario does, the controller being `controller_bin` started on a private Unix link
// (its log in opt.out_dir/controller.log) and stopped at the end (NMT stop; killed if still there 5 s
// later). The run fails (a check result "controller_link" failed) when the controller was lost.
// Throws InputError when ServesScenario(s) is false or the link cannot be set up.
RunResult RunWithControllerProcess(const Scenario& s, RunOptions opt, const std::string& controller_bin,
                                   double timeout_s = 10.0);

}  // namespace exotwin
