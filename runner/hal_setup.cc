// Set-up of a HAL-3 run from its scenario: see hal_setup.h.
#include "runner/hal_setup.h"

#include <algorithm>

#include "core/error.h"
#include "sim/subjects.h"

namespace exotwin {

Hal3PlantParams Hal3PlantParamsOf(const Scenario& s) {
  if (!s.subject.params_file.empty())
    throw InputError(s.source + ": subject.params: device hal3 takes a preset or random_seed subject");
  if (!s.subject.preset.empty()) return Hal3ParamsForSubject(PresetSubject(s.subject.preset));
  if (s.subject.random_seed) return Hal3ParamsForSubject(DrawSubject(*s.subject.random_seed, 0));
  return Hal3PlantParams();
}

MuscleParams OperatorMuscles(const Scenario& s) {
  MuscleParams p = DrawMuscleParams(s.human.muscle_seed);
  p.K0[1] = 1.5;
  p.D0[1] = 0.3;
  return p;
}

controller::HalLoopConfig HalLoopConfigOf(const Scenario& s, const Hal3PlantParams& pp,
                                           const controller::HalEmgCoefficients& emg, double B_v) {
  controller::HalLoopConfig c;
  const std::string& mode = s.hal.mode;
  c.mode = mode == "none" ? controller::HalMode::kNone
                          : (mode == "assist" ? controller::HalMode::kAssist : controller::HalMode::kImpedance);
  c.rate_hz = s.controller.rate_hz;
  c.rms_window = kHalRmsWindow;
  c.tau_max = std::min(60.0, s.controller.torque_limit);
  c.extensor_channel = kHalExtChannel;
  c.flexor_channel = kHalFlexChannel;
  c.velocity.sample_rate_hz = s.controller.rate_hz;
  // tau_c (Lee & Sankai; HKS05 eq. 6): identified exoskeleton (HKS05 eq. 15; the twin hands over its
  // true values: identification itself is tested in tests/controller/hal_assist_test.cc). Inertia
  // is not compensated (I_v = I: a causal acceleration estimate from a potentiometer is too noisy).
  c.impedance.actual = {pp.hal_I(), pp.R, pp.hal_mgl(), pp.C};
  c.impedance.target = {pp.hal_I(), B_v, pp.hal_mgl(), 0.0};
  controller::HalAssistConfig& a = c.assist;
  a.dt = 1.0 / s.controller.rate_hz;
  a.alpha_mu = s.hal.alpha_mu;
  a.alpha_zeta = s.hal.alpha_zeta;
  a.emg = emg;
  a.tau_max = c.tau_max;
  a.rls.dt = a.dt;
  a.rls.R = pp.R;        // HKS05 eq. 15
  a.rls.mgl = pp.mgl();  // HKS05 eq. 14
  a.rls.I0 = pp.I();
  a.rls.gravity_in_input = s.hal.rls_gravity_in_input;
  a.rls.known_inertia = s.hal.rls_known_inertia;
  if (s.hal.rls_friction_in_input) {  // the identified C of tau_c (HKS05 eq. 15), smoothed as tau_c smooths it
    a.friction_C = c.impedance.actual.C;
    a.friction_eps = c.impedance.coulomb_eps;
  }
  return c;
}

}  // namespace exotwin
