#include "diagnosis/fit_families.h"

#include <cmath>
#include <stdexcept>

#include "diagnosis/generate.h"
#include "formats/number_text.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

constexpr double kStrapDynamics = 0.25;  // (motion frequency / strap resonance)^2: resonance >= 2x

std::string Num(double v) { return NumberText(v, 4); }
int J(const Effect& e) { return EffectJoint(e); }

// ---- DESIGN.md's physical ranges (the table "Physical ranges") --------------------------------------
std::string CoulombRange(const Effect& e, const PhysicalScale& s) {
  const double v = e.value, t = s.tau_max[J(e)];
  return v > 0 && v <= 0.5 * t ? "" : "Coulomb friction outside (0, half the largest torque " + Num(0.5 * t) + "] N m";
}
std::string ViscousRange(const Effect& e, const PhysicalScale&) {
  return e.value > 0 ? "" : "negative viscous friction";
}
std::string InertiaRange(const Effect& e, const PhysicalScale& s) {
  const double v = e.value, M = s.M_jj[J(e)];
  return v > -0.5 * M && v < M ? "" : "inertia change outside -50 % .. +100 % of the joint's inertia " + Num(M) + " kg m^2";
}
std::string GravityRange(const Effect& e, const PhysicalScale& s) {
  const double d = s.distal_moment[J(e)];
  return std::abs(e.value) <= 0.5 * d + 0.05 ? "" : "gravity moment change beyond half the distal segments' " + Num(d) + " kg m";
}
std::string StiffnessRange(const Effect& e, const PhysicalScale& s) {
  const int j = J(e);
  const double q0 = e.fields.count("q0") ? e.fields.at("q0") : 0.0;
  if (!(e.value > 0)) return "negative stiffness";
  if (!(q0 >= s.q_min[j] - 0.5 && q0 <= s.q_max[j] + 0.5))
    return "rest angle q0 " + Num(q0) + " rad outside the recorded range widened by 0.5 rad";
  return "";
}
std::string BacklashRange(const Effect& e, const PhysicalScale&) {
  return e.value > 0 && e.value <= 0.1 ? "" : "dead band outside (0, 0.1] rad";
}
// A strap whose RMS static deflection under the torque it carries is below the materiality scale of
// the angle (kMinTorqueShare of its RMS about the mean, as the motion fit's selection) cannot move the
// quasi-static motion by a material amount: what it changes in a simulation is not a strap.
std::string StrapRange(const Effect& e, const PhysicalScale& s) {
  const int j = J(e);
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
std::string RippleRange(const Effect& e, const PhysicalScale& s) {
  return e.value <= 0.5 * s.tau_max[J(e)] ? "" : "ripple beyond half the largest torque";
}
std::string PassiveRange(const Effect& e, const PhysicalScale&) {
  const double v = e.value;
  return v > -1 && v <= kMaxPassiveScale - 1
             ? ""
             : "passive moment " + Num(1 + v) + " times Riener & Edrich's, outside (0, " + Num(kMaxPassiveScale) + "]";
}
std::string OffsetRange(const Effect& e, const PhysicalScale& s) {
  return std::abs(e.value) <= 0.5 * s.tau_max[J(e)] ? "" : "offset beyond half the largest torque";
}
std::string GainRange(const Effect& e, const PhysicalScale&) {
  return e.value >= -0.25 && e.value <= 0.25 ? "" : "gain error outside -25 % .. +25 %";
}
std::string DelayRange(const Effect& e, const PhysicalScale&) {
  return e.value > 0 && e.value <= 0.05 ? "" : "delay outside (0, 50] ms";
}
std::string AnyValue(const Effect&, const PhysicalScale&) { return ""; }
std::string TermRange(const Effect& e, const PhysicalScale&) {
  return std::isfinite(e.value) && e.value != 0 ? "" : "a term of value " + Num(e.value) + " (expected finite, non-zero)";
}

double InertiaEdge(int j, const PhysicalScale& s) { return s.M_jj[j]; }
double GravityEdge(int j, const PhysicalScale& s) { return 0.5 * s.distal_moment[j] + 0.05; }
double HalfTorqueEdge(int j, const PhysicalScale& s) { return 0.5 * s.tau_max[j]; }
double GainEdge(int, const PhysicalScale&) { return 0.25; }

// ---- the effect from the fitted coefficients (the default in ToEffect: value = first coefficient) --
// joint_stiffness: columns -q_j and the offset: value k, k q0 = the offset's coefficient.
void StiffnessEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = d->effect.value;
  d->effect.fields["q0"] = std::abs(v) > 0 ? CoefOf(f, c.cols[1]) / v : 0.0;
}
// series_compliance: the compliance 1/k was fitted; a negative one is no spring.
void StrapEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  d->effect.value = v > 0 ? 1.0 / v : -1.0;
  d->ci_lo = v + 1.96 * se > 0 ? 1.0 / (v + 1.96 * se) : 1.0;
  d->ci_hi = v - 1.96 * se > 0 ? 1.0 / (v - 1.96 * se) : 1e6;
}
// torque_ripple: a sin x + b cos x = A sin(x + phase), A = hypot(a, b), its error propagated.
void RippleEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
  Effect& e = d->effect;
  e.value = std::hypot(v, b);
  const double sA = e.value > 0 ? std::sqrt(std::pow(v * se, 2) + std::pow(b * sb, 2)) / e.value : 0;
  d->ci_lo = e.value - 1.96 * sA, d->ci_hi = e.value + 1.96 * sA;
  e.fields["cycles_per_rad"] = c.ripple_f;
  e.fields["phase"] = std::atan2(b, v);
}
// muscle_activity: value 1, the weights of the channels whose coefficient is beyond 2 standard errors
// (at least the first channel's).
void MuscleEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  Effect& e = d->effect;
  e.value = 1.0, d->ci_lo = d->ci_hi = 1.0;
  for (size_t k = 0; k < c.cols.size(); ++k)
    if (std::abs(CoefOf(f, c.cols[k])) > 2.0 * SeOf(f, c.cols[k])) e.fields["w_" + c.channels[k]] = CoefOf(f, c.cols[k]);
  if (e.fields.empty()) e.fields["w_" + c.channels[0]] = CoefOf(f, c.cols[0]);
}

bool RippleSignificant(const Candidate& c, const Fit& f) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
  return std::hypot(v, b) > kMinT * std::max(se, sb);
}
bool AnyChannelSignificant(const Candidate& c, const Fit& f) {
  bool significant = false;
  for (int col : c.cols) significant |= std::abs(CoefOf(f, col)) > kMinT * SeOf(f, col);
  return significant;
}

// ---- generate's draws (generate.h DrawEffect's ranges) ----------------------------------------------
Effect DrawCoulomb(Rng& rng, int, bool) { Effect e; e.value = rng.Uniform(0.3, 1.5); return e; }
Effect DrawViscous(Rng& rng, int, bool) { Effect e; e.value = rng.Uniform(0.3, 2.0); return e; }
Effect DrawInertia(Rng& rng, int, bool) { Effect e; e.value = rng.Sign() * rng.Uniform(0.05, 0.3); return e; }
Effect DrawGravity(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Sign() * rng.Uniform(0.05, 0.3);
  e.axis = rng.Uniform() < 0.5 ? "X" : "Y";
  return e;
}
Effect DrawStiffness(Rng& rng, int joint, bool one_joint) {
  Effect e;
  e.value = rng.Uniform(3.0, 15.0);
  e.fields["q0"] = one_joint ? rng.Uniform(kGenerateOneJointLo, kGenerateOneJointHi) : rng.Uniform(kGenerateJointLo[joint], kGenerateJointHi[joint]);
  return e;
}
Effect DrawBacklash(Rng& rng, int, bool) { Effect e; e.value = rng.Uniform(0.3, 1.7) * kRadPerDeg; return e; }
// The quasi-static strap model holds well below the strap's resonance sqrt(k / J_c): at the hip J_c
// is the whole leg's (~2.5 kg m^2 against ~0.4 at the knee), so for the same margin above the gait's
// frequencies the hip's straps are drawn stiffer.
Effect DrawStrap(Rng& rng, int joint, bool) {
  Effect e;
  e.value = joint == 0 ? rng.Uniform(800.0, 3000.0) : rng.Uniform(150.0, 800.0);
  return e;
}
Effect DrawRipple(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Uniform(0.2, 1.0);
  e.fields["cycles_per_rad"] = rng.Uniform(2.0, 8.0);
  e.fields["phase"] = rng.Uniform(-M_PI, M_PI);
  return e;
}
Effect DrawOffset(Rng& rng, int, bool) { Effect e; e.value = rng.Sign() * rng.Uniform(0.2, 2.0); return e; }
Effect DrawGain(Rng& rng, int, bool) { Effect e; e.value = rng.Sign() * rng.Uniform(0.02, 0.10); return e; }
Effect DrawDelay(Rng& rng, int, bool) { Effect e; e.value = rng.Uniform(0.005, 0.030); return e; }
Effect DrawMuscle(Rng& rng, int joint, bool) {
  Effect e;
  e.value = 1.0;
  const char* ch[2][2] = {{"GMAX", "RF"}, {"VM", "ST"}};
  for (const char* c : ch[joint]) e.fields[std::string("w_") + c] = rng.Sign() * rng.Uniform(3.0, 10.0);
  return e;
}

// The motion fit's boxes (DESIGN.md's ranges) and secant steps (2 % of the box's scale).
MotionBox CoulombBox(const MotionScale& s) { return {0, 0.5 * s.tau, 0.02 * s.tau}; }
MotionBox ViscousBox(const MotionScale& s) { return {0, 100 * s.tau / s.qd_rms, 0.02 * s.tau / s.qd_rms}; }
MotionBox InertiaBox(const MotionScale& s) { return {-0.45 * s.M, s.M, 0.02 * s.M}; }
MotionBox GravityBox(const MotionScale& s) { return {-s.grav, s.grav, 0.02 * s.grav}; }
MotionBox PassiveBox(const MotionScale&) { return {-0.95, kMaxPassiveScale - 1, 0.05}; }

// Riener & Edrich's curves are a human leg's in HJ15's two-joint angles.
bool TwoJointHuman(const LegParams& p) { return p.human && !p.one_joint; }

FitFamily Row(const char* name, std::string (*implausible)(const Effect&, const PhysicalScale&),
              Effect (*draw)(Rng&, int, bool)) {
  FitFamily f;
  f.family = FindFamily(name);
  if (!f.family) throw std::logic_error(std::string("fit family of no model family: ") + name);
  f.implausible = implausible, f.draw = draw;
  return f;
}

std::deque<FitFamily>& Registry() {
  static std::deque<FitFamily> k = [] {
    std::deque<FitFamily> v;
    FitFamily f = Row("coulomb_friction", CoulombRange, DrawCoulomb);
    f.range_edge = HalfTorqueEdge, f.ceiling_sign = 1, f.linear_column = true, f.motion_box = CoulombBox;
    v.push_back(f);
    f = Row("viscous_friction", ViscousRange, DrawViscous);
    f.ceiling_sign = 1, f.linear_column = true, f.motion_box = ViscousBox;
    v.push_back(f);
    f = Row("inertia_error", InertiaRange, DrawInertia);
    f.range_edge = InertiaEdge, f.linear_column = true, f.motion_box = InertiaBox;
    v.push_back(f);
    f = Row("gravity_error", GravityRange, DrawGravity);
    f.range_edge = GravityEdge, f.linear_column = true, f.axes = {"X", "Y"}, f.motion_box = GravityBox;
    v.push_back(f);
    f = Row("joint_stiffness", StiffnessRange, DrawStiffness);
    f.to_effect = StiffnessEffect, f.ceiling_sign = 1;
    v.push_back(f);
    f = Row("backlash", BacklashRange, DrawBacklash);
    f.ceiling_sign = 1, f.refined_on_exact_form = true;
    v.push_back(f);
    f = Row("series_compliance", StrapRange, DrawStrap);
    f.to_effect = StrapEffect, f.ceiling_sign = 1, f.refined_on_exact_form = true;
    v.push_back(f);
    f = Row("torque_ripple", RippleRange, DrawRipple);
    f.to_effect = RippleEffect, f.significant = RippleSignificant;
    v.push_back(f);
    f = Row("passive_moment", PassiveRange, nullptr);
    f.linear_column = true, f.candidate_for = TwoJointHuman, f.motion_box = PassiveBox;
    v.push_back(f);
    f = Row("sensor_offset", OffsetRange, DrawOffset);
    f.range_edge = HalfTorqueEdge;
    v.push_back(f);
    f = Row("sensor_gain", GainRange, DrawGain);
    f.range_edge = GainEdge;
    v.push_back(f);
    f = Row("sensor_delay", DelayRange, DrawDelay);
    f.ceiling_sign = 1, f.refined_on_exact_form = true;
    v.push_back(f);
    f = Row("muscle_activity", AnyValue, DrawMuscle);
    f.to_effect = MuscleEffect, f.significant = AnyChannelSignificant;
    v.push_back(f);
    // Terms beyond the table: proposed by the term search (diagnosis/term_search*), not a column of the
    // table's fit, not drawn (generate --term hides one).
    v.push_back(Row("term", TermRange, nullptr));
    return v;
  }();
  return k;
}

size_t BuiltInRows() {
  static const size_t n = Registry().size();
  return n;
}

}  // namespace

const std::deque<FitFamily>& FitFamilies() { return Registry(); }

void AddFitFamily(const FitFamily& f) {
  if (!f.family || !f.implausible) throw std::invalid_argument("fit family: expected a model family and a range check");
  for (const FitFamily& g : Registry())
    if (g.family == f.family) throw std::invalid_argument(std::string("fit family '") + f.family->name + "' exists");
  BuiltInRows();  // counted before the first addition
  Registry().push_back(f);
}

void RemoveAddedFitFamily(const std::string& name) {
  if (Registry().size() <= BuiltInRows() || name != Registry().back().family->name)
    throw std::invalid_argument("fit family '" + name + "' is not the row added last");
  Registry().pop_back();
}

const FitFamily* FindFitFamily(const std::string& name) {
  for (const FitFamily& f : FitFamilies())
    if (name == f.family->name) return &f;
  return nullptr;
}

const FitFamily& FitFamilyOf(const std::string& name) {
  if (const FitFamily* f = FindFitFamily(name)) return *f;
  throw std::invalid_argument("no fit row for effect family '" + name + "'");
}

}  // namespace exotwin
