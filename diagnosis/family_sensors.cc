// sensor_offset, sensor_gain and sensor_delay (DESIGN.md "Effects": the reading tau_S of a joint's
// torque sensor): their fit rows and code. First order in the value, a sensor effect moves the reading
// by value times a column of the twin's own reading: 1 (offset), tau_S (gain), -dtau_S/dt (delay; its
// secant at the fitted delay replaces the tangent, stage 3b). The motion fit corrects the reading that
// drives the plant, so its sensor candidates exist where every record's torque reading drives it.
#include <algorithm>
#include <cmath>

#include "core/interpolate.h"
#include "diagnosis/column_tools.h"
#include "diagnosis/family_rows.h"
#include "formats/measured_data.h"

namespace exotwin {
namespace {

std::string OffsetRange(const Effect& e, const PhysicalScale& s) {
  return std::abs(e.value) <= 0.5 * s.tau_max[EffectJoint(e)] ? "" : "offset beyond half the largest torque";
}
std::string GainRange(const Effect& e, const PhysicalScale&) {
  return e.value >= -0.25 && e.value <= 0.25 ? "" : "gain error outside -25 % .. +25 %";
}
std::string DelayRange(const Effect& e, const PhysicalScale&) {
  return e.value > 0 && e.value <= 0.05 ? "" : "delay outside (0, 50] ms";
}
double GainEdge(int, const PhysicalScale&) { return 0.25; }

Effect DrawOffset(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Sign() * rng.Uniform(0.2, 2.0);
  return e;
}
Effect DrawGain(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Sign() * rng.Uniform(0.02, 0.10);
  return e;
}
Effect DrawDelay(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Uniform(0.005, 0.030);
  return e;
}

void OffsetColumns(ColumnContext& x, const FitFamily& self) { x.AddCandidate(self, {x.constant}); }
void GainColumns(ColumnContext& x, const FitFamily& self) {
  const std::vector<double>& tau_S = x.tau_S[x.j];
  x.AddCandidate(self, {AddJointColumn(x.pending, x.w, x.j, [&](size_t i) { return tau_S[i]; })});
}
// The time derivative of the predicted reading, central differences on the record.
void DelayColumns(ColumnContext& x, const FitFamily& self) {
  const std::vector<double>& tau_S = x.tau_S[x.j];
  const std::vector<double>& t = x.kin.t;
  const size_t n = x.n();
  x.AddCandidate(self, {AddJointColumn(x.pending, x.w, x.j, [&](size_t i) {
                   const size_t a = i == 0 ? 0 : i - 1, c = i + 1 < n ? i + 1 : n - 1;
                   return -((tau_S[c] - tau_S[a]) / (t[c] - t[a]));
                 })});
}

// The secant (tau_S(t - d) - tau_S(t)) / d at a delay d in (0.1 ms, 0.5 s).
bool DelaySecant(double d, const Kinematics& kin, const std::vector<double>& tau_S, std::vector<double>* v) {
  if (!(d > 1e-4 && d < 0.5)) return false;
  const size_t n = kin.t.size();
  std::vector<double> tq(n);
  for (size_t i = 0; i < n; ++i) tq[i] = kin.t[i] - d;
  const std::vector<double> shifted = Interpolate(kin.t, tau_S, tq);
  v->assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) (*v)[i] = (shifted[i] - tau_S[i]) / d;
  return true;
}

// The joint's constant input torque is the reading's offset where the reading drives the plant
// (tau_R = -(reading - offset)).
void OffsetMotion(MotionJoint& mj, const FitFamily& self) {
  if (!mj.reading_input) return;
  mj.own(mj.constant, self);
  if (!mj.carried(self)) mj.add_candidate(self, {mj.constant});
}
void GainMotion(MotionJoint& mj, const FitFamily& self) {
  if (mj.reading_input && !mj.carried(self))
    mj.add_candidate(self, {mj.add_parameter(self, self.family->name, {-0.25, 0.25, 0.02}, 0)});
}
void DelayMotion(MotionJoint& mj, const FitFamily& self) {
  if (mj.reading_input && !mj.carried(self))
    mj.add_candidate(self, {mj.add_parameter(self, self.family->name, {0, 0.05, 0.002}, 0)});
}

// A sensor offset o beside a Coulomb friction c at the same joint: the reading tau_S = -tau_R + o
// while the joint moves is that of a friction (c - o) sgn(qd) + ... with no offset only at rest, i.e.
// a direction-dependent friction c - o one way (qd > 0) and c + o the other: the link term
// -o * abs(sgn(qd)) (abs(sgn(qd)) = 1 wherever qd != 0) in the offset's place, exactly. Only a record
// that holds the joint still under a known torque tells the two apart.
bool OffsetAsFrictionAsymmetry(const DiagnosedEffect& e, const std::vector<DiagnosedEffect>& named, EffectAlias* a) {
  const auto coulomb = std::find_if(named.begin(), named.end(), [&](const DiagnosedEffect& d) {
    return d.effect.name == kCoulombFriction && d.effect.joint == e.effect.joint;
  });
  if (coulomb == named.end()) return false;
  Effect t;
  t.name = kTerm, t.joint = e.effect.joint, t.unit = "N m", t.value = -e.effect.value;
  t.expr = "abs(sgn(qd))", t.stage = "link";
  a->effects = {t};
  a->reach_pct = 100, a->left_pct = 0, a->plausible = true;
  return true;
}

bool AnyValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect*) { return true; }
bool PositiveValue(const MotionProblem&, int, const Eigen::VectorXd&, Effect* e) { return e->value > 0; }

}  // namespace

FitFamily SensorOffsetRow() {
  FitFamily f = FitRow("sensor_offset", OffsetRange, DrawOffset);
  f.range_edge = HalfTorqueEdge;
  f.add_columns = OffsetColumns, f.motion_candidates = OffsetMotion, f.motion_effect = AnyValue;
  f.equivalent = OffsetAsFrictionAsymmetry;
  return f;
}

FitFamily SensorGainRow() {
  FitFamily f = FitRow("sensor_gain", GainRange, DrawGain);
  f.range_edge = GainEdge;
  f.add_columns = GainColumns, f.motion_candidates = GainMotion, f.motion_effect = AnyValue;
  return f;
}

FitFamily SensorDelayRow() {
  FitFamily f = FitRow("sensor_delay", DelayRange, DrawDelay);
  f.ceiling_sign = 1, f.refined_on_exact_form = true;
  f.add_columns = DelayColumns, f.secant_column = DelaySecant, f.motion_candidates = DelayMotion;
  f.motion_effect = PositiveValue;
  return f;
}

}  // namespace exotwin
