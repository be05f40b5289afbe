#include "controller/controller_config.h"

#include <cmath>
#include <string>

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

}  // namespace
}  // namespace exotwin::controller
