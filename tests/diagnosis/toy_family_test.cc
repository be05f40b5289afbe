// A family the registry was never given, added by one definition and one registration (this file):
// a drive's quadratic (aerodynamic or churning) drag, tau_R += value * qd |qd|. Nothing else of the
// code names it; it then runs through the model file (written and read), generate (hidden in a
// record), predict (the closed form), the torque fit (named with its value), the forward plant (the
// extended twin's replay carries it as an applied force and gains on the held-out motion) and the
// motion fit (named from its box alone).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "diagnosis/column_tools.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/fit_families.h"
#include "diagnosis/motion_fit.h"
#include "diagnosis/generate.h"
#include "diagnosis/effects.h"
#include "formats/model_file.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

constexpr const char* kToy = "quadratic_drag";

// The family: its identity and closed form (model layer), its fit row (diagnosis layer).
Eigen::Vector2d DragTorque(const Effect& e, const EffectState& s) {
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  const int j = EffectJoint(e);
  t[j] = e.value * s.qd[j] * std::abs(s.qd[j]);
  return t;
}
std::string DragRange(const Effect& e, const PhysicalScale& s) {
  return e.value > 0 && e.value <= s.tau_max[EffectJoint(e)] ? "" : "drag outside (0, the largest torque]";
}
// The motion fit's box: a drag at most half the largest torque at the RMS velocity.
MotionBox DragBox(const MotionScale& s) {
  const double hi = 0.5 * s.tau / (s.qd_rms * s.qd_rms);
  return {0, hi, 0.02 * hi};
}
Effect DrawDrag(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Uniform(2.0, 4.0);
  return e;
}
// The same family through its own code, as a family not linear in its value has it (its file's
// hooks): its torque-fit column built by itself (-qd |qd| at its joint), its motion-fit candidate and
// the effect its parameter stands for.
void DragColumns(ColumnContext& x, const FitFamily& self) {
  const std::vector<double>& qd = x.kin.qd[x.j];
  x.AddCandidate(self, {AddJointColumn(x.pending, x.w, x.j, [&](size_t i) { return -qd[i] * std::abs(qd[i]); })});
}
void DragMotion(MotionJoint& mj, const FitFamily& self) {
  if (!mj.carried(self)) mj.add_candidate(self, {mj.add_parameter(self, self.family->name, DragBox(mj.scale), 0)});
}
bool DragOfValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect* e) { return e->value > 0; }

// Registered for one test (the registry is the process's: the other tests of this executable must not
// see a candidate they were not written for). own_code: through the hooks above instead of the
// generic paths (linear_column, motion_box).
struct ToyFamily {
  explicit ToyFamily(bool own_code = false) {
    EffectFamily f{kToy, "N m s^2/rad^2", 0.0, 100.0, {}, EffectStage::kLink, PlantCarrier::kAppliedForce, "",
                   "tau_R += value * qd |qd|", DragTorque};
    AddEffectFamily(f);
    FitFamily fit;
    fit.family = FindFamily(kToy), fit.implausible = DragRange, fit.draw = DrawDrag, fit.ceiling_sign = 1;
    if (own_code) {
      fit.add_columns = DragColumns, fit.motion_candidates = DragMotion, fit.motion_effect = DragOfValue;
    } else {
      fit.linear_column = true, fit.motion_box = DragBox;
    }
    AddFitFamily(fit);
  }
  ~ToyFamily() {
    RemoveAddedFitFamily(kToy);
    RemoveAddedEffectFamily(kToy);
  }
};

LegParams S1() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml"); }

TEST(ToyFamily, RunsThroughEveryStage) {
  const ToyFamily toy;  // the one registry line
  // The model file writes and reads it.
  LegParams with = S1();
  Effect e;
  e.name = kToy, e.joint = "knee", e.value = 3.0, e.unit = "N m s^2/rad^2";
  with.effects.push_back(e);
  const LegParams back = ParseModelYaml(ModelToYaml(with), "toy.yaml");
  ASSERT_EQ(back.effects.size(), 1u);
  EXPECT_EQ(back.effects[0].name, kToy);
  EXPECT_EQ(back.effects[0].value, 3.0);
  // generate hides it (drawn by its row), at the knee.
  GenerateOptions g;
  g.seed = 4242, g.effects = 1, g.allowed = {kToy}, g.joint = "knee", g.duration = 30, g.rate = 500;
  const GeneratedData data = GenerateMeasured(S1(), g);
  ASSERT_EQ(data.truth.effects.size(), 1u);
  const Effect truth = data.truth.effects[0];
  EXPECT_EQ(truth.name, kToy);
  EXPECT_GE(truth.value, 2.0);
  // predict's effects (ApplyEffects on the rigid twin's torque, here zero): the reading moves by minus
  // the closed form, sample by sample, at the knee only.
  const Kinematics kin = DeriveKinematics(data.data);
  LegParams extended = S1();
  extended.effects = {truth};
  std::vector<double> tau_R[2] = {std::vector<double>(kin.t.size()), std::vector<double>(kin.t.size())};
  std::vector<double> tau_S[2];
  ApplyEffects(extended, kin, tau_R, tau_S);
  for (size_t i = 100; i < kin.t.size(); i += 997) {
    const double qd = kin.qd[1][i];
    EXPECT_NEAR(tau_S[1][i], -truth.value * qd * std::abs(qd), 1e-12) << i;
    EXPECT_EQ(tau_S[0][i], 0.0) << i;
  }
  // The torque fit names it alone, within 15 %, and the extended twin's forward simulation (the plant
  // applying it each step) follows the held-out motion closer than the rigid twin.
  DiagnoseOptions opt;
  opt.threads = 2;
  const Diagnosis d = Diagnose(S1(), data.data, opt);
  ASSERT_EQ(d.effects.size(), 1u) << (d.effects.empty() ? "nothing" : d.effects[0].effect.name);
  EXPECT_EQ(d.effects[0].effect.name, kToy);
  EXPECT_EQ(d.effects[0].effect.joint, "knee");
  EXPECT_NEAR(d.effects[0].effect.value, truth.value, 0.15 * truth.value);
  EXPECT_GE(d.joints[1].gain_pct, 50);
  ASSERT_TRUE(d.simulation.done) << d.simulation.note;
  EXPECT_LT(d.simulation.split[1].rmse_after, d.simulation.split[1].rmse_before);
  // The motion fit (the forward plant on the record's windows) names it too, from its box alone, and
  // nothing else at the knee.
  opt.fit = DiagnoseFit::kMotion;
  const Diagnosis m = Diagnose(S1(), data.data, opt);
  std::string named;
  const DiagnosedEffect* drag = nullptr;
  int at_knee = 0;
  for (const auto& x : m.effects) {
    named += " " + x.effect.name + "(" + x.effect.joint + ") = " + std::to_string(x.effect.value);
    if (x.effect.name == kToy) drag = &x;
    at_knee += x.effect.joint == "knee";
  }
  std::printf("motion fit named:%s (truth %g)\n", named.c_str(), truth.value);
  ASSERT_NE(drag, nullptr) << named;
  EXPECT_EQ(drag->effect.joint, "knee");
  EXPECT_EQ(at_knee, 1) << named;
  EXPECT_NEAR(drag->effect.value, truth.value, 0.15 * truth.value);
}

// A family's own hooks take the generic paths' place: the torque fit names it with the value the
// generic column gives (the same column, at another place in the bank), and the motion fit's
// candidate (its box from the hook) stands for the drag at the parameter's value.
TEST(ToyFamily, OwnCodeAsHooksMatchesTheGenericPaths) {
  GenerateOptions g;
  g.seed = 4242, g.effects = 1, g.allowed = {kToy}, g.joint = "knee", g.duration = 30, g.rate = 500;
  DiagnoseOptions opt;
  opt.threads = 2;
  GeneratedData data;
  double generic = 0;
  {
    const ToyFamily toy;
    data = GenerateMeasured(S1(), g);
    const Diagnosis d = Diagnose(S1(), data.data, opt);
    ASSERT_EQ(d.effects.size(), 1u);
    generic = d.effects[0].effect.value;
  }
  const ToyFamily toy(true);
  const Diagnosis d = Diagnose(S1(), data.data, opt);
  ASSERT_EQ(d.effects.size(), 1u) << (d.effects.empty() ? "nothing" : d.effects[0].effect.name);
  EXPECT_EQ(d.effects[0].effect.name, kToy);
  EXPECT_EQ(d.effects[0].effect.joint, "knee");
  EXPECT_NEAR(d.effects[0].effect.value, generic, 1e-9 * generic);
  // The motion fit's candidate at each joint, in the box DragBox gives the knee's scales.
  const MotionProblem P(S1(), {&data.data}, opt);
  const int c = P.CandidateIndex(kToy, "knee");
  ASSERT_GE(c, 0);
  ASSERT_GE(P.CandidateIndex(kToy, "hip"), 0);
  const int k = P.candidates()[static_cast<size_t>(c)].cols[0];
  EXPECT_EQ(P.lower(k), 0.0);
  const double qd = P.qd_rms(1);
  EXPECT_NEAR(P.upper(k), 0.5 * std::max(P.scale().tau_max[1], 1e-3) / (qd * qd), 1e-12 * P.upper(k));
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(P.parameters());
  theta[k] = 2.5;
  const std::vector<Effect> fx = P.EffectsOf(theta);
  ASSERT_EQ(fx.size(), 1u);
  EXPECT_EQ(fx[0].name, kToy);
  EXPECT_EQ(fx[0].joint, "knee");
  EXPECT_EQ(fx[0].value, 2.5);
  EXPECT_EQ(fx[0].unit, "N m s^2/rad^2");
  theta[k] = -1;  // a drag below its box names nothing (DragOfValue)
  EXPECT_TRUE(P.EffectsOf(theta).empty());
}

}  // namespace
}  // namespace exotwin
