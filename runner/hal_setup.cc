// Set-up of a HAL-3 run from its scenario: see hal_setup.h.
#include "runner/hal_setup.h"

#include <algorithm>

#include "core/error.h"
#include "runner/hal_emg_calibration.h"
#include "sim/subjects.h"
#include "sim/synthetic_emg.h"

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
  c.rms_window = kHalRmsWindow;
  c.tau_max = std::min(60.0, s.controller.torque_limit);
  c.extensor_channel = kHalExtChannel;
  c.flexor_channel = kHalFlexChannel;
  // tau_c (Lee & Sankai; HKS05 eq. 6): identified exoskeleton (HKS05 eq. 15; the twin hands over its
  // true values: identification itself is tested in tests/controller/hal_assist_test.cc). Inertia
  // is not compensated (I_v = I: a causal acceleration estimate from a potentiometer is too noisy).
  c.impedance.actual = {pp.hal_I(), pp.R, pp.hal_mgl(), pp.C};
  c.impedance.target = {pp.hal_I(), B_v, pp.hal_mgl(), 0.0};
  controller::HalAssistConfig& a = c.assist;
  a.alpha_mu = s.hal.alpha_mu;
  a.alpha_zeta = s.hal.alpha_zeta;
  a.emg = emg;
  a.rls.R = pp.R;        // HKS05 eq. 15
  a.rls.mgl = pp.mgl();  // HKS05 eq. 14
  a.rls.I0 = pp.I();
  a.rls.gravity_in_input = s.hal.rls_gravity_in_input;
  a.rls.known_inertia = s.hal.rls_known_inertia;
  if (s.hal.rls_friction_in_input) {  // the identified C of tau_c (HKS05 eq. 15), smoothed as tau_c smooths it
    a.friction_C = c.impedance.actual.C;
    a.friction_eps = c.impedance.coulomb_eps;
  }
  controller::SetRateAndLimit(&c, s.controller.rate_hz);
  return c;
}

int HalRuns(const Scenario& s) {
  return s.hal.sweep_viscosity.empty() ? s.protocol.trials : static_cast<int>(s.hal.sweep_viscosity.size());
}

double HalRunViscosity(const Scenario& s, int run) {
  return s.hal.sweep_viscosity.empty() ? s.hal.virtual_viscosity : s.hal.sweep_viscosity.at(static_cast<size_t>(run));
}

uint64_t HalRunSeed(const Scenario& s, uint64_t seed, int run) {
  return seed * 7919ull + static_cast<uint64_t>(s.hal.sweep_viscosity.empty() ? run : 0);
}

controller::HalEmgCoefficients HalRunCalibration(const Scenario& s, const MuscleParams& operator_muscles,
                                                 uint64_t run_seed) {
  const HalEmgCalibrationSpec cal{kHalExtChannel, kHalFlexChannel, kHalRmsWindow, s.hal.calibration_levels, 0.02,
                                  s.hal.calibration_hi, s.hal.calibration_rest};
  return CalibrateHalEmg(operator_muscles, DefaultSyntheticEmgConfig(), cal, run_seed + 11);
}

controller::ControllerFile HalControllerFile(const Scenario& s, const controller::HalLoopConfig& loop) {
  controller::ControllerFile f;
  f.source = s.source;
  f.controller = s.controller;
  f.controller.feedforward = false;
  f.driver_limit = std::min(60.0, s.hardware.torque_limit);
  f.trials = HalRuns(s);
  f.hal = loop;
  return f;
}

controller::ControllerFile HalControllerFileOf(const Scenario& s, uint64_t seed, int run) {
  const uint64_t run_seed = HalRunSeed(s, seed, run);
  const Hal3PlantParams pp = Hal3PlantParamsOf(s);
  return HalControllerFile(s, HalLoopConfigOf(s, pp, HalRunCalibration(s, OperatorMuscles(s), run_seed),
                                              HalRunViscosity(s, run)));
}

}  // namespace exotwin
