// EMG calibration exercise of HKS05 eq. 2: see hal_emg_calibration.h.
#include "runner/hal_emg_calibration.h"

#include <array>
#include <cmath>
#include <vector>

#include "dsp/emg_envelope.h"
#include "hwsim/emg_amplifier.h"

namespace exotwin {

controller::HalEmgCoefficients CalibrateHalEmg(const MuscleParams& p, const SyntheticEmgConfig& emg_cfg,
                                   const HalEmgCalibrationSpec& spec, uint64_t seed) {
  // Blocks: extension (VM + RF) and flexion (ST + GAS) alternating; within a group the drive is
  // proportional to alpha, as the operator's own allocation of a knee torque (sim/muscles.h).
  const int ext[2] = {static_cast<int>(Muscle::kVM), static_cast<int>(Muscle::kRF)};
  const int flx[2] = {static_cast<int>(Muscle::kST), static_cast<int>(Muscle::kGAS)};
  const double a_ext = std::max(p.alpha(ext[0], 1), p.alpha(ext[1], 1));
  const double a_flx = std::max(p.alpha(flx[0], 1), p.alpha(flx[1], 1));
  std::vector<ContractionBlock> blocks;
  const double t_rest0 = 0.5, t_rest1 = t_rest0 + spec.rest;  // relaxed: baseline E0
  double t0 = t_rest1;
  for (int k = 0; k < spec.levels; ++k) {
    const double level = spec.lo + (spec.hi - spec.lo) * k / std::max(1, spec.levels - 1);
    for (int dir = 0; dir < 2; ++dir) {
      ContractionBlock b;
      b.t_start = t0;
      b.ramp = 0.5;
      b.hold = 1.5;
      for (int i = 0; i < 2; ++i) {
        const int m = dir == 0 ? ext[i] : flx[i];
        b.peak[m] = level * p.alpha(m, 1) / (dir == 0 ? a_ext : a_flx);
      }
      blocks.push_back(b);
      t0 += 2 * b.ramp + b.hold + 1.0;
    }
  }
  ContractionProgramme prog(blocks);
  MuscleModel muscles(p, 1e-3);
  SyntheticEmg emg(emg_cfg, seed);
  hwsim::EmgAmplifier amp;
  dsp::RmsEnvelope rms_e(1000.0, spec.rms_window), rms_f(1000.0, spec.rms_window);
  const Eigen::Vector2d q(1.5707963267948966, -1.5707963267948966), qd(0, 0);  // th_HAL = 0
  std::vector<double> Ee, te, Ef, tf;
  double pe = 0, pf = 0;  // summed envelope power at rest, V^2
  long n_rest = 0;
  const long n = static_cast<long>(prog.duration() / 1e-3) + 1000;
  for (long k = 0; k < n; ++k) {
    const double t = k * 1e-3;
    muscles.Step(prog.Excitation(t, q, qd));
    const MuscleVec raw = emg.Sample(muscles.electrical_activation());
    std::array<double, hwsim::EmgAmplifier::kChannels> v{};
    for (int c = 0; c < kNumMuscles; ++c) v[c] = raw[c];
    const auto out = amp.Sample(v);
    const double E_e = rms_e.Step(out[spec.extensor_channel]);
    const double E_f = rms_f.Step(out[spec.flexor_channel]);
    if (t < t_rest0) continue;  // filter start-up
    if (t < t_rest1) pe += E_e * E_e, pf += E_f * E_f, ++n_rest;
    const double tau = ContractionTorque(p, muscles.mechanical_activation(), q, qd)[1];  // HAL reads it
    // Each group's line is fitted on its own contractions and the rests (torque 0 there).
    if (tau >= 0) Ee.push_back(E_e), te.push_back(tau);
    if (tau <= 0) Ef.push_back(E_f), tf.push_back(-tau);
  }
  controller::HalEmgCoefficients c;
  if (spec.noise_correction && n_rest > 0) {
    c.baseline_e = std::sqrt(pe / n_rest);
    c.baseline_f = std::sqrt(pf / n_rest);
    for (double& E : Ee) E = controller::NoiseCorrectedEnvelope(E, c.baseline_e);
    for (double& E : Ef) E = controller::NoiseCorrectedEnvelope(E, c.baseline_f);
  }
  c.extensor = controller::FitEmgToTorque(Ee, te);
  c.flexor = controller::FitEmgToTorque(Ef, tf);
  return c;
}

}  // namespace exotwin
