// Hayashi's EMG calibration exercise (HKS05 eq. 2, sec. II-A) in the twin: the knee is held at th = 0 by
// HAL (isometric) while the operator extends, then flexes, against a steady reference torque at
// several levels without co-contraction. The electrode voltages go through the same amplifier
// (hwsim) and the controller's RMS envelope (HKS05 eq. 1); a least-squares line maps each envelope to the
// torque of its muscle group (FitEmgToTorque). Nothing here is ground truth handed to the controller:
// it only sees envelopes and the produced torque, as in the paper's Fig. 3.
#pragma once
#include <cstdint>

#include "controller/hal_assist.h"
#include "sim/muscles.h"
#include "sim/synthetic_emg.h"

namespace exotwin {

struct HalEmgCalibrationSpec {
  int extensor_channel = 1;  // VM
  int flexor_channel = 3;    // ST
  double rms_window = 0.1;   // s, HKS05 eq. 1
  int levels = 4;            // contraction levels per direction, evenly from lo to hi
  double lo = 0.02, hi = 0.12;  // fraction of MVC: the range of a seated swing (our choice)
  // Relaxed rest at the start (s, after 0.5 s of filter start-up): the mean envelope power there
  // gives each channel's baseline E0, and HKS05 eq. 2 is fitted on the noise-corrected envelopes
  // (NoiseCorrectedEnvelope in controller/hal_assist.h). false: the paper's fit on raw E.
  double rest = 1.5;
  bool noise_correction = true;
};

// Runs the calibration exercise with the subject's muscles `p` and EMG `emg` (seeded by `seed`);
// returns the HKS05 eq. 2 coefficients (a in N m/V, b in N m) and the relaxed baselines (V).
// Deterministic for a seed.
controller::HalEmgCoefficients CalibrateHalEmg(const MuscleParams& p, const SyntheticEmgConfig& emg,
                                   const HalEmgCalibrationSpec& spec, uint64_t seed);

}  // namespace exotwin
