// backlash and series_compliance (DESIGN.md "Effects"): their fit rows and code, in one file because
// they share one internal hinge per joint (their exclusive group) and one pass over the samples for
// their torque-fit columns, each first order in its value:
//   backlash: Delta tau_S = (b/2) s(tau_R,j) dtau/dq_j (effects.h's dead band, s = tanh(. / width));
//   series_compliance: Delta tau_S = (1/k) dtau_C/dq_j tau_C,j (the compliant part's deflection).
// Both are refined on the exact form after the linear fit (ExtendAndRefine).
#include <algorithm>
#include <cmath>

#include "core/units.h"
#include "diagnosis/column_tools.h"
#include "diagnosis/effects.h"
#include "diagnosis/family_rows.h"
#include "formats/number_text.h"
#include "model/passive_torque.h"
#include "model/regressors.h"

namespace exotwin {
namespace {

constexpr double kStrapDynamics = 0.25;  // (motion frequency / strap resonance)^2: resonance >= 2x
constexpr double kNoBacklash = 1e-5;     // rad: a narrower dead band is none (the hinge is not built)
constexpr double kNoCompliance = 1e-7;   // rad/(N m): a stiffer strap is none

std::string Num(double v) { return NumberText(v, 4); }

std::string BacklashRange(const Effect& e, const PhysicalScale&) {
  return e.value > 0 && e.value <= 0.1 ? "" : "dead band outside (0, 0.1] rad";
}
// A strap whose RMS static deflection under the torque it carries is below the materiality scale of
// the angle (kMinTorqueShare of its RMS about the mean, as the motion fit's selection) cannot move the
// quasi-static motion by a material amount: what it changes in a simulation is not a strap.
std::string StrapRange(const Effect& e, const PhysicalScale& s) {
  const int j = EffectJoint(e);
  const double v = e.value, range = s.q_max[j] - s.q_min[j], angle_floor = kMinTorqueShare * s.q_rms[j];
  if (!(v > 0 && s.tau_C_max[j] / v <= 0.5 * range))
    return "strap deflection " + Num(v > 0 ? s.tau_C_max[j] / v : 0) + " rad beyond half the motion range";
  if (!(s.tau_C_rms[j] / v >= angle_floor))
    return "strap deflection " + Num(s.tau_C_rms[j] / v) + " rad RMS, below the angle's materiality " +
           Num(angle_floor) + " rad";
  if (!(s.strap_dynamics[j] / v <= kStrapDynamics))
    return "strap resonance sqrt(k / J) at " + Num(std::sqrt(v / s.strap_dynamics[j])) +
           " times the motion's frequency, expected above " + Num(1 / std::sqrt(kStrapDynamics)) +
           " (the quasi-static strap model)";
  return "";
}

// The compliance 1/k was fitted; a negative one is no spring.
void StrapEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  d->effect.value = v > 0 ? 1.0 / v : -1.0;
  d->ci_lo = v + 1.96 * se > 0 ? 1.0 / (v + 1.96 * se) : 1.0;
  d->ci_hi = v - 1.96 * se > 0 ? 1.0 / (v - 1.96 * se) : 1e6;
}

Effect DrawBacklash(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Uniform(0.3, 1.7) * kRadPerDeg;
  return e;
}
// The quasi-static strap model holds well below the strap's resonance sqrt(k / J_c): at the hip J_c
// is the whole leg's (~2.5 kg m^2 against ~0.4 at the knee), so for the same margin above the gait's
// frequencies the hip's straps are drawn stiffer.
Effect DrawStrap(Rng& rng, int joint, bool) {
  Effect e;
  e.value = joint == 0 ? rng.Uniform(800.0, 3000.0) : rng.Uniform(150.0, 800.0);
  return e;
}

// The actuator torque R[k] = ActuatorTorque(rigid, x_k, qd, qdd) and the compliant part's torque
// C[k] = CompliantPartTorque(rigid, x_k, qd, qdd) at x_0 = q, x_1 = q + h e_j, x_2 = q - h e_j (h = kNearStep),
// equal to them up to rounding: each point's rigid torque in the regressor form Y(x_k, qd, qdd) theta
// (HJ15 eq. 18-21, model/regressors.h), one Y for both parameter sets, the sines and cosines of the
// shifted angles from those of q by the angle-addition formulas (3 sincos per sample instead of 24),
// and each point's passive moment computed once (in both), the three from one set of exponentials
// (model/passive_torque.h PassiveNearPoints, made for j and kNearStep). `total`: rigid.Total().
struct NearTorques {
  Eigen::Vector2d R[3], C[3];
};
constexpr double kNearStep = 1e-5;  // rad
NearTorques TorquesNear(const LegParams& rigid, const LumpedParams& total, const PassiveNearPoints& near_passive, int j,
                        const Eigen::Vector2d& q, const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  constexpr double kH = kNearStep;
  static const double ch = std::cos(kH), sh = std::sin(kH);
  RegressorTrig trig[3];
  trig[0] = TrigOf(q);
  trig[1] = trig[2] = trig[0];
  // sin(a +- h) = s ch +- c sh, cos(a +- h) = c ch -+ s sh, for the angles that move with q_j: th1 and
  // th1 + th2 (j = 0) or th2 and th1 + th2 (j = 1).
  auto shift = [](double* s_out, double* c_out, double s, double c, double sign) {
    *s_out = s * ch + sign * c * sh;
    *c_out = c * ch - sign * s * sh;
  };
  for (int k = 1; k < 3; ++k) {
    const double sign = k == 1 ? 1.0 : -1.0;
    RegressorTrig& t = trig[k];
    if (j == 0) shift(&t.s1, &t.c1, trig[0].s1, trig[0].c1, sign);
    else shift(&t.s2, &t.c2, trig[0].s2, trig[0].c2, sign);
    shift(&t.s12, &t.c12, trig[0].s12, trig[0].c12, sign);
  }
  const Vector6 theta_R = ToVector(total);
  NearTorques t;
  Eigen::Vector2d passive[3];
  if (rigid.human) near_passive.At(q, passive);
  for (int k = 0; k < 3; ++k) {
    const Matrix26 Y = FullRegressorOfTrig(rigid.L1, rigid.g, trig[k], qd, qdd);
    t.R[k] = Y * theta_R;
    if (!rigid.human) {  // no human: the compliant part is the whole chain
      t.C[k] = t.R[k];
      continue;
    }
    t.C[k] = Y * ToVector(*rigid.human) + passive[k];
    t.R[k] += passive[k];
  }
  return t;
}

// Both families' columns in one pass over the samples, the dead band's candidate then the strap's.
void HingeColumns(ColumnContext& x, const FitFamily& self) {
  ColumnBank& b = x.bank;
  const int j = x.j;
  const Kinematics& kin = x.kin;
  const int cb = NewColumn(b), cs = NewColumn(b);
  const PassiveNearPoints near_passive(x.rigid.passive, j, kNearStep);
  AddColumnPair(x.pending, x.w, cb, cs, [&](size_t i, Eigen::Vector2d* backlash, Eigen::Vector2d* strap) {
    const NearTorques t = TorquesNear(x.rigid, x.total, near_passive, j, {kin.q[0][i], kin.q[1][i]},
                                      {kin.qd[0][i], kin.qd[1][i]}, {kin.qdd[0][i], kin.qdd[1][i]});
    const Eigen::Vector2d d = (t.R[1] - t.R[2]) / 2e-5;
    *backlash = Eigen::Vector2d(0.5 * std::tanh(t.R[0][j] / kBacklashTorqueWidth) * d);
    const Eigen::Vector2d dc = (t.C[1] - t.C[2]) / 2e-5;
    *strap = Eigen::Vector2d(dc * t.C[0][j]);
  });
  x.AddCandidate(self, {cb});
  x.AddCandidate(FitFamilyOf("series_compliance"), {cs});
}

void BacklashMotion(MotionJoint& mj, const FitFamily& self) {
  if (!mj.carried(self)) mj.add_candidate(self, {mj.add_parameter(self, self.family->name, {0, 0.1, 0.005}, 0)});
}
// The strap's parameter is its compliance 1/k: a deflection up to half the range under the largest
// torque the compliant part carries. The plant carries a strap with a human at the knee only.
void StrapMotion(MotionJoint& mj, const FitFamily& self) {
  if (mj.carried(self) || (mj.j == 0 && mj.params->human)) return;
  const double tc = std::max(mj.scale.tau_C, 1e-3);
  mj.add_candidate(self, {mj.add_parameter(self, self.family->name, {0, 0.5 * mj.scale.range / tc, 0.005 / tc}, 0)});
}

bool BacklashOfValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect* e) { return e->value > kNoBacklash; }
bool StrapOfValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect* e) {
  if (!(e->value > kNoCompliance)) return false;
  e->value = 1 / e->value;
  return true;
}

void StrapValues(const Effect& e, const Candidate& cand, Eigen::VectorXd* theta) {
  (*theta)[cand.cols[0]] = e.value > 0 ? 1 / e.value : 0;
}

std::string NoStrapCandidate(const Effect& e, const LegParams& params) {
  return e.joint == "hip" && params.human ? "the plant carries a strap with a human at the knee only" : "";
}

}  // namespace

FitFamily BacklashRow() {
  FitFamily f = FitRow("backlash", BacklashRange, DrawBacklash);
  f.ceiling_sign = 1, f.refined_on_exact_form = true;
  f.add_columns = HingeColumns, f.motion_candidates = BacklashMotion, f.motion_effect = BacklashOfValue;
  return f;
}

FitFamily SeriesComplianceRow() {
  FitFamily f = FitRow("series_compliance", StrapRange, DrawStrap);
  f.to_effect = StrapEffect, f.ceiling_sign = 1, f.refined_on_exact_form = true;
  f.motion_candidates = StrapMotion, f.motion_effect = StrapOfValue, f.torque_values = StrapValues;
  f.no_motion_candidate = NoStrapCandidate;
  return f;
}

}  // namespace exotwin
