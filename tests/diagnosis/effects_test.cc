// The extended twin's effect models (diagnosis/effects.h): backlash, series compliance, muscle
// activity, and the generator's determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "diagnosis/effects.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "core/error.h"
#include "core/units.h"
#include "model/leg_dynamics.h"

namespace exotwin {
namespace {

LegParams S1() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml"); }

Kinematics Static(double q1, double q2, size_t n = 300, double dt = 1e-3) {
  Kinematics k;
  for (size_t i = 0; i < n; ++i) {
    k.t.push_back(i * dt);
    k.q[0].push_back(q1), k.q[1].push_back(q2);
    for (int j = 0; j < 2; ++j) k.qd[j].push_back(0), k.qdd[j].push_back(0);
  }
  return k;
}

void Rigid(const LegParams& p, const Kinematics& k, std::vector<double> tr[2]) {
  for (int j = 0; j < 2; ++j) tr[j].clear();
  for (size_t i = 0; i < k.t.size(); ++i) {
    const Eigen::Vector2d t = ActuatorTorque(p, {k.q[0][i], k.q[1][i]}, {k.qd[0][i], k.qd[1][i]},
                                             {k.qdd[0][i], k.qdd[1][i]});
    tr[0].push_back(t[0]), tr[1].push_back(t[1]);
  }
}

TEST(Effects, BacklashLinkLagsHalfTheBandAgainstTheLoad) {
  LegParams p = S1();
  const Kinematics k = Static(0.3, -0.8);
  std::vector<double> tr[2], ts[2];
  Rigid(p, k, tr);
  const double tau_knee = tr[1][0];
  ASSERT_GT(std::abs(tau_knee), 1.0);
  p.effects.push_back({"backlash", "knee", 0.02, "rad", {}, ""});
  ApplyEffects(p, k, tr, ts);
  // Held statically: the link sits b/2 behind the motor against the gravity load.
  LegParams rigid = p;
  rigid.effects.clear();
  const double s = tau_knee > 0 ? 1.0 : -1.0;
  const Eigen::Vector2d expect = ActuatorTorque(rigid, {0.3, -0.8 - 0.01 * s}, {0, 0}, {0, 0});
  EXPECT_NEAR(-ts[1][100], expect[1], 1e-6);
  EXPECT_NEAR(-ts[0][100], expect[0], 1e-6);
}

TEST(Effects, SeriesComplianceDeflectsTheHumanByItsTorqueOverK) {
  LegParams p = S1();
  const Kinematics k = Static(0.4, -0.6);
  const double K = 300;
  const Eigen::Vector2d qc = CompliantAngle(p, 1, K, {0.4, -0.6}, {0, 0}, {0, 0});
  const Eigen::Vector2d tc = CompliantPartTorque(p, qc, {0, 0}, {0, 0});
  EXPECT_NEAR(qc[1], -0.6 - tc[1] / K, 1e-10);  // the spring carries the human's torque
  EXPECT_EQ(qc[0], 0.4);
  std::vector<double> tr[2], ts[2];
  Rigid(p, k, tr);
  const double before = tr[1][0];
  p.effects.push_back({"series_compliance", "knee", K, "N m/rad", {}, ""});
  ApplyEffects(p, k, tr, ts);
  EXPECT_GT(std::abs(-ts[1][0] - before), 1e-3);
  // A very stiff strap is the rigid twin.
  LegParams stiff = S1();
  stiff.effects.push_back({"series_compliance", "knee", 1e6, "N m/rad", {}, ""});
  Rigid(S1(), k, tr);
  ApplyEffects(stiff, k, tr, ts);
  EXPECT_NEAR(-ts[1][0], before, 1e-3);
}

TEST(Effects, MuscleActivityUsesTheEmgEnvelope) {
  LegParams p = S1();
  Kinematics k = Static(0.3, -0.5, 4000);
  std::vector<double> emg(4000);
  for (size_t i = 0; i < emg.size(); ++i) emg[i] = 0.2 * ((i % 2) ? 1.0 : -1.0);  // 500 Hz square
  k.emg["VM"] = emg;
  const std::vector<double> env = EmgEnvelope(k.t, emg);
  EXPECT_NEAR(env[2000], 0.2 * 0.9, 0.05);  // rectified amplitude (minus the high-pass loss)
  std::vector<double> tr[2], ts[2];
  Rigid(p, k, tr);
  const double before = tr[1][2000];
  Effect e{"muscle_activity", "knee", 1.0, "-", {{"w_VM", 5.0}}, ""};
  p.effects.push_back(e);
  ApplyEffects(p, k, tr, ts);
  EXPECT_NEAR(-ts[1][2000] - before, 5.0 * env[2000], 1e-9);
  // Weight for a channel the data lack: bad input naming the column.
  p.effects[0].fields = {{"w_GAS", 1.0}};
  Rigid(S1(), k, tr);
  try {
    ApplyEffects(p, k, tr, ts);
    FAIL() << "expected InputError";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("emg_GAS"), std::string::npos);
  }
}

TEST(Effects, ExtendedModelFileRoundTrips) {
  LegParams p = S1();
  p.effects.push_back({"muscle_activity", "hip", 1.0, "-", {{"w_GMAX", -4.0}, {"w_RF", 2.5}}, ""});
  p.effects.push_back({"backlash", "knee", 0.01, "rad", {}, ""});
  p.effects.push_back({"series_compliance", "hip", 400, "N m/rad", {}, ""});
  const LegParams q = ParseModelYaml(ModelToYaml(p), "roundtrip");
  ASSERT_EQ(q.effects.size(), 3u);
  EXPECT_EQ(q.effects[0].fields.at("w_GMAX"), -4.0);
  EXPECT_EQ(q.effects[2].value, 400);
}

TEST(Generate, SameSeedSameBitsOtherSeedOtherData) {
  GenerateOptions g;
  g.seed = 42, g.duration = 5, g.rate = 500;
  const GeneratedData a = GenerateMeasured(S1(), g), b = GenerateMeasured(S1(), g);
  EXPECT_EQ(a.data.tau_knee(), b.data.tau_knee());
  EXPECT_EQ(ModelToYaml(a.truth), ModelToYaml(b.truth));
  g.seed = 43;
  EXPECT_NE(GenerateMeasured(S1(), g).data.tau_knee(), a.data.tau_knee());
  // Angles stay in the stated ranges.
  for (double q : a.data.q_hip()) EXPECT_TRUE(q > 4.9 * kRadPerDeg && q < 40.1 * kRadPerDeg);
  for (double q : a.data.q_knee()) EXPECT_TRUE(q > -70.1 * kRadPerDeg && q < -4.9 * kRadPerDeg);
}

TEST(Generate, RejectsBadOptions) {
  GenerateOptions g;
  g.duration = 1;
  EXPECT_THROW(GenerateMeasured(S1(), g), InputError);
  g.duration = 10, g.allowed = {"levitation"};
  EXPECT_THROW(GenerateMeasured(S1(), g), InputError);
}

}  // namespace
}  // namespace exotwin
