#include "controller/controller_config.h"

#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "core/error.h"

namespace exotwin::controller {
namespace {

const char* kGood = R"(
controller: {rate_hz: 1000, kp: [600, 400], kd: [30, 15], feedforward: true, torque_limit: 100}
drivers: {torque_limit: 120}
model:
  L1: 0.41
  exo: {J1: 3.01, J2: 0.74, X1: 3.85, X2: 1.73, Y1: 0.14, Y2: 0.18}
  human: {J1: 1.5, J2: 0.3, X1: 2.1, X2: 0.9, Y1: 0, Y2: 0}
  passive: riener1999
reference: {kind: excitation, moving_joint: knee, excitation_seed: 3, ramp: 0.5, hold: {hip: 1.2}}
trials: 2
)";

std::string ErrorOf(const std::string& text) {
  try {
    ParseControllerFile(text, "ctl.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ControllerConfig, ReadsEveryPart) {
  const ControllerFile f = ParseControllerFile(kGood, "ctl.yaml");
  EXPECT_EQ(f.controller.kp[1], 400);
  EXPECT_EQ(f.controller.kd[0], 30);
  EXPECT_EQ(f.driver_limit, 120);
  EXPECT_EQ(f.model.L1, 0.41);
  ASSERT_TRUE(f.model.human);
  EXPECT_EQ(f.model.human->X1, 2.1);
  EXPECT_EQ(f.model.passive, PassiveModel::kRiener1999);
  EXPECT_EQ(f.reference.kind, ReferenceKind::kExcitation);
  EXPECT_EQ(f.reference.moving_joint, "knee");
  EXPECT_EQ(*f.reference.hold_hip, 1.2);
  EXPECT_FALSE(f.reference.hold_knee);
  EXPECT_EQ(f.trials, 2);
  const ExoControllerConfig c = ExoConfigOf(f);
  EXPECT_EQ(c.safety.hip.tau_sensor_max, 115.0);
  EXPECT_EQ(c.safety.knee.tau_cmd_max, 100 + 1e-6);
  EXPECT_EQ(c.knee.kp, 400);
}

TEST(ControllerConfig, WrittenFileReadsBackBitForBit) {
  ControllerFile f = ParseControllerFile(kGood, "ctl.yaml");
  f.model.exo.J1 = 0.1 + 0.2;  // not a short decimal
  f.model.human->Y2 = -1.0 / 3.0;
  f.reference.hold_knee = -M_PI / 2;
  const ControllerFile g = ParseControllerFile(ControllerFileYaml(f, "test"), "round.yaml");
  EXPECT_EQ(g.model.exo.J1, f.model.exo.J1);
  EXPECT_EQ(g.model.human->Y2, f.model.human->Y2);
  EXPECT_EQ(*g.reference.hold_knee, *f.reference.hold_knee);
  EXPECT_EQ(*g.reference.hold_hip, *f.reference.hold_hip);
  EXPECT_EQ(g.reference.excitation_seed, 3u);
  EXPECT_EQ(g.trials, 2);
  // The same reference, sample for sample.
  const auto a = BuildReference(f.reference, 1), b = BuildReference(g.reference, 1);
  for (double t : {0.0, 0.25, 1.7, 9.3}) {
    JointSetpoint ha, ka, hb, kb;
    a->Sample(t, &ha, &ka);
    b->Sample(t, &hb, &kb);
    EXPECT_EQ(ha.q, hb.q);
    EXPECT_EQ(ka.qd, kb.qd);
  }
}

TEST(ControllerConfig, BadFilesNameTheKey) {
  auto without = [](const std::string& key) {  // key: "kp: [600, 400]" and the like, with its ", "
    std::string t = kGood;
    return t.erase(t.find(key), key.size() + 2);
  };
  EXPECT_NE(ErrorOf(without("kp: [600, 400]")).find("ctl.yaml: controller.kp: missing"), std::string::npos);
  EXPECT_NE(ErrorOf(without("kd: [30, 15]")).find("controller.kd: missing"), std::string::npos);
  std::string over = kGood;
  over.replace(over.find("torque_limit: 100"), 17, "torque_limit: 150");
  EXPECT_NE(ErrorOf(over).find("controller.torque_limit: 150 N m is beyond the drivers' range"), std::string::npos)
      << ErrorOf(over);
  std::string no_model = kGood;
  no_model.erase(no_model.find("model:"), no_model.find("reference:") - no_model.find("model:"));
  EXPECT_NE(ErrorOf(no_model).find("model: missing"), std::string::npos) << ErrorOf(no_model);
  EXPECT_NE(ErrorOf("name: x\ndevice: exowheel\n").find("controller.yaml"), std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kGood) + "gains: 1\n").find("gains"), std::string::npos);
  std::string bad_exo = kGood;
  bad_exo.replace(bad_exo.find("Y2: 0.18"), 8, "Y3: 0.18");
  EXPECT_NE(ErrorOf(bad_exo).find("model.exo"), std::string::npos);
}

// A HAL-3 controller file: every field of the loop's configuration travels, bit for bit (each set to
// a value no short decimal gives), and the rate-derived fields follow controller.rate_hz.
TEST(ControllerConfig, HalFileCarriesTheWholeLoopBitForBit) {
  ControllerFile f;
  f.controller.rate_hz = 500;
  f.controller.torque_limit = 100;
  f.driver_limit = 60;
  f.trials = 3;
  HalLoopConfig c;
  c.mode = HalMode::kAssist;
  c.extensor_channel = 2, c.flexor_channel = 4, c.velocity.order = 3;
  c.rms_window = 0.1 + 0.2 / 3, c.emg_fs = 1000.0 / 3, c.tau_max = 40.0 / 3, c.status_timeout = 0.02 / 3;
  c.velocity.velocity_cutoff_hz = 20.0 / 3, c.velocity.acceleration_cutoff_hz = 10.0 / 7;
  c.impedance.actual = {0.3 / 7, 0.2 / 3, 9.81 / 7, 0.4 / 3};
  c.impedance.target = {0.3 / 11, 1.56 / 7, 9.81 / 11, 0.0};
  c.impedance.coulomb_eps = 0.05 / 3;
  HalAssistConfig& a = c.assist;
  a.alpha_mu = 1.0 / 3, a.alpha_zeta = 0.5 / 3, a.lambda1 = 60.0 / 7, a.lambda2 = 80.0 / 7;
  a.friction_C = 0.4 / 7, a.friction_eps = 0.05 / 7;
  a.emg.extensor = {123.0 / 7, -1.0 / 3}, a.emg.flexor = {99.0 / 7, 2.0 / 3};
  a.emg.baseline_e = 1e-4 / 3, a.emg.baseline_f = 2e-4 / 7;
  a.rls.rho = 0.999 - 1e-5 / 3, a.rls.p0 = 1e6 / 3, a.rls.p_max = 1e9 / 7, a.rls.pf = 20.0 / 3;
  a.rls.R = 0.2 / 3, a.rls.mgl = 9.81 / 3, a.rls.I0 = 0.3 / 7, a.rls.D0 = 1.0 / 7, a.rls.K0 = 5.0 / 7;
  a.rls.gravity_in_input = true, a.rls.known_inertia = true;
  f.hal = c;
  const ControllerFile g = ParseControllerFile(ControllerFileYaml(f, "test"), "hal.yaml");
  ASSERT_TRUE(g.hal);
  const HalLoopConfig& h = *g.hal;
  EXPECT_EQ(h.mode, HalMode::kAssist);
  EXPECT_EQ(h.extensor_channel, 2);
  EXPECT_EQ(h.flexor_channel, 4);
  EXPECT_EQ(h.velocity.order, 3);
  EXPECT_EQ(h.rms_window, c.rms_window);
  EXPECT_EQ(h.emg_fs, c.emg_fs);
  EXPECT_EQ(h.tau_max, c.tau_max);
  EXPECT_EQ(h.status_timeout, c.status_timeout);
  EXPECT_EQ(h.velocity.velocity_cutoff_hz, c.velocity.velocity_cutoff_hz);
  EXPECT_EQ(h.velocity.acceleration_cutoff_hz, c.velocity.acceleration_cutoff_hz);
  for (const auto& [x, y] : {std::pair{h.impedance.actual, c.impedance.actual}, std::pair{h.impedance.target, c.impedance.target}}) {
    EXPECT_EQ(x.I, y.I);
    EXPECT_EQ(x.B, y.B);
    EXPECT_EQ(x.mgl, y.mgl);
    EXPECT_EQ(x.C, y.C);
  }
  EXPECT_EQ(h.impedance.coulomb_eps, c.impedance.coulomb_eps);
  const HalAssistConfig& b = h.assist;
  EXPECT_EQ(b.alpha_mu, a.alpha_mu);
  EXPECT_EQ(b.alpha_zeta, a.alpha_zeta);
  EXPECT_EQ(b.lambda1, a.lambda1);
  EXPECT_EQ(b.lambda2, a.lambda2);
  EXPECT_EQ(b.friction_C, a.friction_C);
  EXPECT_EQ(b.friction_eps, a.friction_eps);
  EXPECT_EQ(b.emg.extensor.a, a.emg.extensor.a);
  EXPECT_EQ(b.emg.extensor.b, a.emg.extensor.b);
  EXPECT_EQ(b.emg.flexor.a, a.emg.flexor.a);
  EXPECT_EQ(b.emg.flexor.b, a.emg.flexor.b);
  EXPECT_EQ(b.emg.baseline_e, a.emg.baseline_e);
  EXPECT_EQ(b.emg.baseline_f, a.emg.baseline_f);
  EXPECT_EQ(b.rls.rho, a.rls.rho);
  EXPECT_EQ(b.rls.p0, a.rls.p0);
  EXPECT_EQ(b.rls.p_max, a.rls.p_max);
  EXPECT_EQ(b.rls.pf, a.rls.pf);
  EXPECT_EQ(b.rls.R, a.rls.R);
  EXPECT_EQ(b.rls.mgl, a.rls.mgl);
  EXPECT_EQ(b.rls.I0, a.rls.I0);
  EXPECT_EQ(b.rls.D0, a.rls.D0);
  EXPECT_EQ(b.rls.K0, a.rls.K0);
  EXPECT_TRUE(b.rls.gravity_in_input);
  EXPECT_TRUE(b.rls.known_inertia);
  // Derived from controller.rate_hz and hal.tau_max as the runner's HalLoopConfigOf sets them.
  EXPECT_EQ(h.rate_hz, 500);
  EXPECT_EQ(h.velocity.sample_rate_hz, 500);
  EXPECT_EQ(b.dt, 1.0 / 500);
  EXPECT_EQ(b.rls.dt, 1.0 / 500);
  EXPECT_EQ(b.tau_max, c.tau_max);
  EXPECT_EQ(g.trials, 3);
  EXPECT_FALSE(g.controller.feedforward);

  // Bad HAL files name the key.
  const std::string text = ControllerFileYaml(f, "test");
  std::string missing = text;
  const size_t at = missing.find("      rho:");
  missing.erase(at, missing.find('\n', at) + 1 - at);
  EXPECT_NE(ErrorOf(missing).find("hal.assist.rls.rho: missing"), std::string::npos) << ErrorOf(missing);
  const struct {
    const char *from, *to, *key;
  } edits[] = {{"drivers: {torque_limit: 60}", "drivers: {torque_limit: 10}", "hal.tau_max"},
               {"mode: assist", "mode: boost", "hal.mode"},
               {"    lambda1:", "    lambda9:", "hal.assist"},
               {"extensor_channel: 2", "extensor_channel: 7", "hal.extensor_channel"}};
  for (const auto& e : edits) {
    std::string bad = text;
    const size_t where = bad.find(e.from);
    ASSERT_NE(where, std::string::npos) << e.from;
    bad.replace(where, std::strlen(e.from), e.to);
    EXPECT_NE(ErrorOf(bad).find(e.key), std::string::npos) << ErrorOf(bad);
  }
}

}  // namespace
}  // namespace exotwin::controller
