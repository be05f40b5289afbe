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

// A motion through qd = 0 starting at t = 5 s (a term's t counts from the record's start).
Kinematics Swing(size_t n = 400, double dt = 2e-3) {
  Kinematics k;
  for (size_t i = 0; i < n; ++i) {
    const double t = 5.0 + i * dt;
    k.t.push_back(t);
    k.q[0].push_back(0.3 * std::sin(2 * t)), k.q[1].push_back(-0.8 + 0.4 * std::sin(3 * t + 1));
    k.qd[0].push_back(0.6 * std::cos(2 * t)), k.qd[1].push_back(1.2 * std::cos(3 * t + 1));
    k.qdd[0].push_back(-1.2 * std::sin(2 * t)), k.qdd[1].push_back(-3.6 * std::sin(3 * t + 1));
  }
  return k;
}

Effect Term(const char* joint, double value, const char* expr, const char* stage = "") {
  Effect e;
  e.name = "term", e.joint = joint, e.value = value, e.unit = "N m", e.expr = expr, e.stage = stage;
  return e;
}

// predict's term "sgn(qd)" is coulomb_friction's form; a term reads the rigid torque (before any
// effect) and the time from the record's start; a sensor term adds to the reading in the listed order.
TEST(Effects, TermsAgainstTheirClosedForms) {
  const LegParams rigid = S1();
  const Kinematics k = Swing();
  std::vector<double> r0[2];
  Rigid(rigid, k, r0);
  auto apply = [&](const std::vector<Effect>& effects, std::vector<double> tr[2], std::vector<double> ts[2]) {
    LegParams p = rigid;
    p.effects = effects;
    tr[0] = r0[0], tr[1] = r0[1];
    ApplyEffects(p, k, tr, ts);
  };
  Effect coulomb;
  coulomb.name = "coulomb_friction", coulomb.joint = "knee", coulomb.value = 1.0, coulomb.unit = "N m";
  std::vector<double> ta[2], sa[2], tb[2], sb[2];
  apply({coulomb}, ta, sa);
  apply({Term("knee", 1.0, "1.0*sgn(qd)")}, tb, sb);
  for (int j = 0; j < 2; ++j)
    for (size_t i = 0; i < k.t.size(); ++i) {
      ASSERT_NEAR(tb[j][i], ta[j][i], 1e-12) << j << " " << i;
      ASSERT_NEAR(sb[j][i], sa[j][i], 1e-12) << j << " " << i;
    }
  // A load-dependent friction at the hip after a viscous friction there: tau_R in expr is the rigid one.
  Effect viscous = coulomb;
  viscous.name = "viscous_friction", viscous.joint = "hip", viscous.value = 2.0;
  apply({viscous, Term("hip", 0.06, "abs(tau_R) * sgn(qd)"), Term("knee", 0.5, "t - q_hip * qd_knee"),
         Term("knee", -0.01, "tau_R * abs(tau_R)", "sensor"), Term("hip", 3.0, "qdd", "sensor")},
        ta, sa);
  for (size_t i = 0; i < k.t.size(); ++i) {
    const double sg = k.qd[0][i] > 0 ? 1 : (k.qd[0][i] < 0 ? -1 : 0);
    const double hip = r0[0][i] + 2.0 * k.qd[0][i] + 0.06 * std::abs(r0[0][i]) * sg;
    const double knee = r0[1][i] + 0.5 * ((k.t[i] - 5.0) - k.q[0][i] * k.qd[1][i]);
    ASSERT_NEAR(ta[0][i], hip, 1e-12) << i;
    ASSERT_NEAR(ta[1][i], knee, 1e-12) << i;
    ASSERT_NEAR(sa[0][i], -hip + 3.0 * k.qdd[0][i], 1e-12) << i;
    ASSERT_NEAR(sa[1][i], -knee - 0.01 * r0[1][i] * std::abs(r0[1][i]), 1e-12) << i;
  }
}

TEST(Effects, TermsRoundTripThroughTheModelFile) {
  LegParams p = S1();
  p.effects = {Term("knee", 0.061, "abs(tau_R) * sgn(qd)"), Term("hip", -0.0016, "tau_R * abs(tau_R)", "sensor")};
  const LegParams q = ParseModelYaml(ModelToYaml(p), "extended.yaml");
  ASSERT_EQ(q.effects.size(), 2u);
  EXPECT_EQ(q.effects[0].expr, "abs(tau_R) * sgn(qd)");
  EXPECT_EQ(q.effects[1].stage, "sensor");
  EXPECT_EQ(StageOf(q.effects[1]), EffectStage::kSensor);
  EXPECT_EQ(StageOf(q.effects[0]), EffectStage::kLink);
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

// generate's hidden terms draw nothing from the seed: with and without them the record differs by the
// terms' closed forms (at the generated angles, to the encoder's quantization) within the torque
// sensor's resolution; a bad term is refused naming --term and the position.
TEST(Generate, HiddenTermsAreTheirClosedForms) {
  GenerateOptions g;
  g.seed = 7, g.effects = 0, g.duration = 4, g.rate = 500;
  const GeneratedData clean = GenerateMeasured(S1(), g);
  g.terms = {Term("knee", 0.7, "2 * sin(q) + t / 30"), Term("hip", -0.4, "q_knee^2 * (1 + pos(q - 0.4))", "sensor")};
  const GeneratedData hidden = GenerateMeasured(S1(), g);
  ASSERT_EQ(hidden.truth.effects.size(), 2u);
  EXPECT_EQ(hidden.truth.effects[1].stage, "sensor");
  EXPECT_EQ(hidden.data.q_knee(), clean.data.q_knee());
  const std::vector<double>& t = clean.data.t();
  const std::vector<double>&qh = clean.data.q_hip(), &qk = clean.data.q_knee();
  const double res = 0.005;  // the sensor's resolution (generate.h)
  double worst[2] = {0, 0};
  for (size_t i = 0; i < t.size(); ++i) {
    // tau_S = -tau_R: a link term lowers the reading by its torque; a sensor term adds to it.
    const double knee = -0.7 * (2 * std::sin(qk[i]) + t[i] / 30);
    const double hip = -0.4 * qk[i] * qk[i] * (1 + (qh[i] > 0.4 ? 1 : 0));
    worst[0] = std::max(worst[0], std::abs(hidden.data.tau_hip()[i] - clean.data.tau_hip()[i] - hip));
    worst[1] = std::max(worst[1], std::abs(hidden.data.tau_knee()[i] - clean.data.tau_knee()[i] - knee));
  }
  EXPECT_LE(worst[0], res + 1e-4);
  EXPECT_LE(worst[1], res + 1e-4);
  EXPECT_GT(worst[1], 0.0);
  g.terms = {Term("knee", 1.0, "abs(tau_R) * sgn(qdx)")};
  try {
    GenerateMeasured(S1(), g);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--term \"abs(tau_R) * sgn(qdx)\": unknown signal 'qdx'"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("position 17"), std::string::npos) << e.what();
  }
  g.terms = {Term("ankle", 1.0, "q")};
  EXPECT_THROW(GenerateMeasured(S1(), g), InputError);
}

}  // namespace
}  // namespace exotwin
