#include "diagnosis/fit_families.h"

#include <cmath>
#include <stdexcept>

#include "diagnosis/family_rows.h"
#include "formats/number_text.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

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
std::string PassiveRange(const Effect& e, const PhysicalScale&) {
  const double v = e.value;
  return v > -1 && v <= kMaxPassiveScale - 1
             ? ""
             : "passive moment " + Num(1 + v) + " times Riener & Edrich's, outside (0, " + Num(kMaxPassiveScale) + "]";
}
std::string TermRange(const Effect& e, const PhysicalScale&) {
  return std::isfinite(e.value) && e.value != 0 ? "" : "a term of value " + Num(e.value) + " (expected finite, non-zero)";
}

double InertiaEdge(int j, const PhysicalScale& s) { return s.M_jj[j]; }
double GravityEdge(int j, const PhysicalScale& s) { return 0.5 * s.distal_moment[j] + 0.05; }

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
// The motion fit's boxes (DESIGN.md's ranges) and secant steps (2 % of the box's scale).
MotionBox CoulombBox(const MotionScale& s) { return {0, 0.5 * s.tau, 0.02 * s.tau}; }
MotionBox ViscousBox(const MotionScale& s) { return {0, 100 * s.tau / s.qd_rms, 0.02 * s.tau / s.qd_rms}; }
MotionBox InertiaBox(const MotionScale& s) { return {-0.45 * s.M, s.M, 0.02 * s.M}; }
MotionBox GravityBox(const MotionScale& s) { return {-s.grav, s.grav, 0.02 * s.grav}; }
MotionBox PassiveBox(const MotionScale&) { return {-0.95, kMaxPassiveScale - 1, 0.05}; }

// Riener & Edrich's curves are a human leg's in HJ15's two-joint angles.
bool TwoJointHuman(const LegParams& p) { return p.human && !p.one_joint; }
std::string NoPassiveCandidate(const Effect&, const LegParams&) {
  return "no passive moment in this model (a two-joint model with a human carries it)";
}

// The friction's forms exchanged by the motion fit: the torque at the joint's RMS speed (the same
// power dissipated there), Coulomb c = viscous b qd_rms.
double CoulombAtSpeed(double v, double) { return v; }
double ViscousTorque(double b, double qd_rms) { return b * qd_rms; }
double ViscousValue(double torque, double qd_rms) { return torque / qd_rms; }

std::deque<FitFamily>& Registry() {
  static std::deque<FitFamily> k = [] {
    std::deque<FitFamily> v;
    FitFamily f = FitRow("coulomb_friction", CoulombRange, DrawCoulomb);
    f.range_edge = HalfTorqueEdge, f.ceiling_sign = 1, f.linear_column = true, f.motion_box = CoulombBox;
    f.exchanged_with = "viscous_friction", f.torque_at_speed = CoulombAtSpeed, f.value_at_speed = CoulombAtSpeed;
    v.push_back(f);
    f = FitRow("viscous_friction", ViscousRange, DrawViscous);
    f.ceiling_sign = 1, f.linear_column = true, f.motion_box = ViscousBox;
    f.exchanged_with = "coulomb_friction", f.torque_at_speed = ViscousTorque, f.value_at_speed = ViscousValue;
    v.push_back(f);
    f = FitRow("inertia_error", InertiaRange, DrawInertia);
    f.range_edge = InertiaEdge, f.linear_column = true, f.motion_box = InertiaBox;
    v.push_back(f);
    f = FitRow("gravity_error", GravityRange, DrawGravity);
    f.range_edge = GravityEdge, f.linear_column = true, f.axes = {"X", "Y"}, f.motion_box = GravityBox;
    v.push_back(f);
    v.push_back(JointStiffnessRow());
    v.push_back(BacklashRow());
    v.push_back(SeriesComplianceRow());
    v.push_back(TorqueRippleRow());
    f = FitRow("passive_moment", PassiveRange, nullptr);
    f.linear_column = true, f.candidate_for = TwoJointHuman, f.motion_box = PassiveBox;
    f.no_motion_candidate = NoPassiveCandidate;
    v.push_back(f);
    v.push_back(SensorOffsetRow());
    v.push_back(SensorGainRow());
    v.push_back(SensorDelayRow());
    v.push_back(MuscleActivityRow());
    // Terms beyond the table: proposed by the term search (diagnosis/term_search*), not a column of the
    // table's fit, not drawn (generate --term hides one).
    v.push_back(FitRow(kTerm, TermRange, nullptr));
    return v;
  }();
  return k;
}

size_t BuiltInRows() {
  static const size_t n = Registry().size();
  return n;
}

}  // namespace

FitFamily FitRow(const char* name, std::string (*implausible)(const Effect&, const PhysicalScale&),
                 Effect (*draw)(Rng&, int, bool)) {
  FitFamily f;
  f.family = FindFamily(name);
  if (!f.family) throw std::logic_error(std::string("fit family of no model family: ") + name);
  f.implausible = implausible, f.draw = draw;
  return f;
}

double HalfTorqueEdge(int j, const PhysicalScale& s) { return 0.5 * s.tau_max[j]; }

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
