// The EXOwheel closed-loop runner (device exowheel or exowheel_exo_only): per trial, the MuJoCo leg +
// exoskeleton, the joint modules and the subject's muscles and EMG on the co-simulation rig
// (runner/cosim_rig.h) with the real ExoController tracking the protocol's trajectory (gait,
// identification excitation or hold); faults switch on and off as the scenario says.
#pragma once
#include "runner/runner.h"

namespace exotwin {

// Runs every trial of an EXOwheel scenario (RunScenario's dispatch): writes DIR/result.json,
// DIR/measured[_trialN].csv (the rig's view: encoder angles, torque-sensor readings, commands, EMG)
// and DIR/truth[_trialN].csv (plant state, applied and muscle torques); with opt.video_path, the
// first trial's video. Throws InputError on bad scenario content and SimulationError on divergence.
RunResult RunExowheelScenario(const Scenario& s, const RunOptions& opt);

}  // namespace exotwin
