// joint_stiffness (DESIGN.md "Effects": tau_R += value * (q - q0)): its fit row and code. The torque
// fit's candidate is linear in (k, k q0): the columns -q_j and the joint's constant; the motion fit's
// likewise (its k, and k q0 in the joint's constant input torque).
#include <cmath>

#include "diagnosis/column_tools.h"
#include "diagnosis/family_rows.h"
#include "diagnosis/generate.h"
#include "formats/number_text.h"

namespace exotwin {
namespace {

std::string StiffnessRange(const Effect& e, const PhysicalScale& s) {
  const int j = EffectJoint(e);
  const double q0 = e.fields.count("q0") ? e.fields.at("q0") : 0.0;
  if (!(e.value > 0)) return "negative stiffness";
  if (!(q0 >= s.q_min[j] - 0.5 && q0 <= s.q_max[j] + 0.5))
    return "rest angle q0 " + NumberText(q0, 4) + " rad outside the recorded range widened by 0.5 rad";
  return "";
}

// Columns -q_j and the offset: value k, k q0 = the offset's coefficient.
void StiffnessEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = d->effect.value;
  d->effect.fields["q0"] = std::abs(v) > 0 ? CoefOf(f, c.cols[1]) / v : 0.0;
}

Effect DrawStiffness(Rng& rng, int joint, bool one_joint) {
  Effect e;
  e.value = rng.Uniform(3.0, 15.0);
  e.fields["q0"] = one_joint ? rng.Uniform(kGenerateOneJointLo, kGenerateOneJointHi)
                             : rng.Uniform(kGenerateJointLo[joint], kGenerateJointHi[joint]);
  return e;
}

void StiffnessColumns(ColumnContext& x, const FitFamily& self) {
  const int j = x.j;
  const Kinematics& kin = x.kin;
  x.AddCandidate(self, {AddJointColumn(x.pending, x.w, j, [&](size_t i) { return -kin.q[j][i]; }), x.constant});
}

// Its box: up to 100 times the largest torque per RMS angle about the mean.
void StiffnessMotion(MotionJoint& mj, const FitFamily& self) {
  if (mj.carried(self)) return;
  const MotionScale& s = mj.scale;
  const MotionBox box{0, 100 * s.tau / s.q_rms, 0.02 * s.tau / s.q_rms};
  mj.add_candidate(self, {mj.add_parameter(self, self.family->name, box, 0), mj.constant});
}

// A positive stiffness; its constant part k q0 is the constant parameter's (q0 = 0 here).
bool StiffnessOfValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect* e) {
  if (!(e->value > 0)) return false;
  e->fields["q0"] = 0;
  return true;
}

void StiffnessValues(const Effect& e, const Candidate& cand, Eigen::VectorXd* theta) {
  (*theta)[cand.cols[0]] = e.value;
  (*theta)[cand.cols[1]] = e.value * (e.fields.count("q0") ? e.fields.at("q0") : 0.0);
}

}  // namespace

FitFamily JointStiffnessRow() {
  FitFamily f = FitRow("joint_stiffness", StiffnessRange, DrawStiffness);
  f.to_effect = StiffnessEffect, f.ceiling_sign = 1;
  f.add_columns = StiffnessColumns, f.motion_candidates = StiffnessMotion, f.motion_effect = StiffnessOfValue;
  f.torque_values = StiffnessValues;
  return f;
}

}  // namespace exotwin
