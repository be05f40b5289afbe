// The HAL-3 scenario runner (device: hal3): Hayashi's seated knee swing and Lee & Sankai's virtual
// impedance sweep, on the lockstep co-simulation rig (runner/cosim_rig.h) like the EXOwheel runner:
//   Hal3Plant (MuJoCo) + MuscleModel/KneeSwingBehaviour (operator) + SyntheticEmg
//   -> Hal3KneeNode (potentiometer, strain gauge) and EmgNode (amplifier) -> HalKneeStatus / EmgSamples
//   -> controller::HalLoop (real controller code) -> HalKneeCommand -> motor driver -> plant.
// Metrics (result.json) per run, after hal.settle s; phases as Hayashi sec. IV: swing-up th > 0,
// thd > 0; swing-down th > 0, thd < 0 (true state):
//   emg_ext_up_V, emg_ext_down_V, emg_flex_up_V, emg_flex_down_V  mean RMS envelope (HKS05 eq. 1) the
//       controller saw per phase (Fig. 9-A/B "average myoelectric activity"), V after gain 1000;
//   emg_ext_up_rect_V  mean rectified extensor EMG in swing-up, V;
//   strain_up_Nm, strain_down_Nm  mean strain-gauge torque per phase (Fig. 9-C/D);
//   mu_ext_up_Nm  mean extensor contraction torque in swing-up (truth);
//   J_tau_m  LS05 eq. 12: mean |musculoskeletal moment| (truth), N m;
//   J_e, J_f  LS05 eq. 15-16: integral of |extensor| / |flexor| EMG, V s;
//   rls_D_mean, rls_K_mean, truth_D_mean, truth_K_mean, rls_D_err_pct, rls_K_err_pct (assist mode;
//       truth = the rho-weighted least-squares D, K of the operator's true viscoelastic torque, the
//       quantity the RLS identifies, see hal_runner.cc); truth_D_timemean, truth_K_timemean: plain
//       time means of D(t), K(t), for information;
//   emg_a_ext, emg_a_flex, emg_b_ext, emg_b_flex, emg_baseline_ext_V, emg_baseline_flex_V: the
//       HKS05 eq. 2 calibration (N m/V, N m) and the relaxed envelopes subtracted in quadrature (V);
//   th_max, th_min (rad), tracking_rms_rad (against the intended swing).
// With hal.sweep_viscosity, one run per B_v; per-run metrics get the suffix "@<B_v>", plus
// sweep_argmin_viscosity (B_v of the smallest J_tau_m), sweep_min_J_tau_m, and sweep.csv.
#pragma once
#include "runner/runner.h"

namespace exotwin {

// Runs a device: hal3 scenario; writes DIR/result.json, DIR/measured[_trialN].csv (t, q_knee,
// tau_knee = strain gauge, cmd_knee, emg_GMAX..emg_GAS, E_ext, E_flex, mu_hat, D_hat, K_hat) and
// DIR/truth[_trialN].csv. Throws InputError on bad content (e.g. device not hal3, subject params
// file) and SimulationError on divergence.
RunResult RunHalScenario(const Scenario& s, const RunOptions& opt);

}  // namespace exotwin
