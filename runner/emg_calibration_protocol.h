// The EMG-to-torque calibration of Hwang & Jeon 2015 sec. 4.3 (after Olney & Winter 1985) as one
// EXOwheel scenario (`emg_calibration:` block, DESIGN.md): every trial runs on the twin and the
// calibration is computed from what the rig RECORDED (EMG amplifier output, encoder angles, torque
// sensors), never from the ground truth:
//   1. MVC trials of each muscle against manual resistance (the examiner, not the exoskeleton: the
//      paper's MVCs do not go through the torque sensors), EMG through the amplifier -> mvc/*.csv;
//      MVC = mean of the trial peaks of the 2 Hz linear envelope;
//   2. isometric trials per joint, the exoskeleton holding the pose (runner, behaviour
//      isometric_hip / isometric_knee) -> HJ15 eq. 25 alpha against tau_S minus its relaxed reading,
//      R^2 / NRMS per direction (Table 6);
//   3. with `dynamic`: exaggerated gait at 2 km/h (runner, behaviour exaggerated_gait), tau_M of
//      HJ15 eq. 9 from tau_S and the inverse dynamics of three parameter sets (identified = the
//      subject's Table 4 parameters, De Leva and Dempster from sim/anthropometry), HJ15 eq. 28 beta,
//      gamma per joint and model (Table 7).
#pragma once
#include "runner/runner.h"

namespace exotwin {

// Runs scenario s (s.emg_calibration set). Writes DIR/mvc/mvc_<MUSCLE>.csv (t, emg_* in V),
// DIR/isometric_{hip,knee}/ and DIR/gait/ (the runner's measured.csv, truth.csv, result.json),
// DIR/calibration.csv, DIR/calibration.json and DIR/result.json; metrics as in DESIGN.md.
// Throws InputError on bad scenario content, SimulationError on divergence.
RunResult RunEmgCalibrationScenario(const Scenario& s, const RunOptions& opt);

}  // namespace exotwin
