#include "model/effect_families.h"

#include <cmath>
#include <stdexcept>

#include "core/interpolate.h"
#include "model/passive_torque.h"

namespace exotwin {

const char* const kCoulombFriction = "coulomb_friction";
const char* const kViscousFriction = "viscous_friction";
const char* const kInertiaError = "inertia_error";
const char* const kGravityError = "gravity_error";
const char* const kJointStiffness = "joint_stiffness";
const char* const kBacklash = "backlash";
const char* const kSeriesCompliance = "series_compliance";
const char* const kTorqueRipple = "torque_ripple";
const char* const kPassiveMoment = "passive_moment";
const char* const kSensorOffset = "sensor_offset";
const char* const kSensorGain = "sensor_gain";
const char* const kSensorDelay = "sensor_delay";
const char* const kMuscleActivity = "muscle_activity";
const char* const kTerm = "term";

namespace {

// value * f at the effect's joint, 0 at the other.
Eigen::Vector2d AtJoint(const Effect& e, double f) {
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  t[EffectJoint(e)] = f;
  return t;
}

Eigen::Vector2d Coulomb(const Effect& e, const EffectState& s) {
  return AtJoint(e, e.value * CoulombSign(s.qd[EffectJoint(e)]));
}
Eigen::Vector2d Viscous(const Effect& e, const EffectState& s) { return AtJoint(e, e.value * s.qd[EffectJoint(e)]); }
Eigen::Vector2d Inertia(const Effect& e, const EffectState& s) { return AtJoint(e, e.value * s.qdd[EffectJoint(e)]); }
Eigen::Vector2d Gravity(const Effect& e, const EffectState& s) { return GravityErrorTorque(e, s.g, s.q); }
Eigen::Vector2d Stiffness(const Effect& e, const EffectState& s) {
  return AtJoint(e, e.value * (s.q[EffectJoint(e)] - e.fields.at("q0")));
}
Eigen::Vector2d Ripple(const Effect& e, const EffectState& s) {
  return AtJoint(e, TorqueRippleTorque(e, s.q[EffectJoint(e)]));
}
Eigen::Vector2d Passive(const Effect& e, const EffectState& s) { return AtJoint(e, PassiveMomentTorque(e, s.q)); }
// DESIGN.md "Terms beyond the table": value * expr at the joint (added to tau_R, or to tau_S at the
// sensor stage).
Eigen::Vector2d Term(const Effect& e, const EffectState& s) {
  return AtJoint(e, e.value * CachedTermExpr(e.expr).Eval(TermSignalsAt(e, s)));
}

// DESIGN.md: tau_S += offset, tau_S *= 1 + gain, tau_S(t) = true reading at t - delay.
void Offset(const Effect& e, const std::vector<double>&, std::vector<double>* tau_S) {
  for (double& v : *tau_S) v += e.value;
}
void Gain(const Effect& e, const std::vector<double>&, std::vector<double>* tau_S) {
  for (double& v : *tau_S) v *= 1.0 + e.value;
}
void Delay(const Effect& e, const std::vector<double>& t, std::vector<double>* tau_S) {
  std::vector<double> tq(t.size());
  for (size_t i = 0; i < t.size(); ++i) tq[i] = t[i] - e.value;
  *tau_S = Interpolate(t, *tau_S, tq);
}

void OffsetOff(double v, const std::vector<double>&, std::vector<double>* tau_S) {
  for (double& x : *tau_S) x -= v;
}
void GainOff(double v, const std::vector<double>&, std::vector<double>* tau_S) {
  for (double& x : *tau_S) x /= 1.0 + v;
}
// The reading at t + delay is the torque at t.
void DelayOff(double v, const std::vector<double>& t, std::vector<double>* tau_S) {
  if (v == 0) return;
  std::vector<double> tq(t.size());
  for (size_t i = 0; i < t.size(); ++i) tq[i] = t[i] + v;
  *tau_S = Interpolate(t, *tau_S, tq);
}
void OffsetAffine(double v, double*, double* b) { *b += v; }
void GainAffine(double v, double* a, double* b) { *a *= 1 + v, *b *= 1 + v; }

using S = EffectStage;
using C = PlantCarrier;
using K = EffectKey::Kind;

std::deque<EffectFamily>& Registry() {
  static std::deque<EffectFamily> k = {
      {kCoulombFriction, "N m", 0.0, 100.0, {}, S::kLink, C::kFrictionLoss, "",
       "tau_R += value * sign(qd) (value > 0)", Coulomb},
      {kViscousFriction, "N m s/rad", -100.0, 100.0, {}, S::kLink, C::kDamping, "", "tau_R += value * qd",
       Viscous},
      {kInertiaError, "kg m^2", -10.0, 10.0, {}, S::kLink, C::kArmature, "",
       "tau_R += value * qdd (extra inertia of that joint alone, like armature)", Inertia},
      {kGravityError, "kg m", -20.0, 20.0, {}, S::kLink, C::kAppliedForce, "",
       "the lumped X or Y (field `axis`) of the segment distal to that joint is off by value", Gravity, nullptr,
       nullptr, nullptr, {{"axis", K::kAxis}}},
      {kJointStiffness, "N m/rad", -1000.0, 1000.0, {"q0"}, S::kLink, C::kSpring, "",
       "tau_R += value * (q - q0) (field `q0`, rad)", Stiffness},
      // One internal hinge per joint: a dead band and a strap at one joint are one hinge too many.
      {kBacklash, "rad", 0.0, 0.5, {}, S::kLink, C::kDeadBandHinge, "internal_hinge",
       "the transmission has a dead band of total width value"},
      {kSeriesCompliance, "N m/rad", 1.0, 1e6, {}, S::kLink, C::kStrapHinge, "internal_hinge",
       "the link follows the exoskeleton through a spring of that stiffness (straps, cuffs)"},
      {kTorqueRipple, "N m", 0.0, 100.0, {"cycles_per_rad", "phase"}, S::kLink, C::kAppliedForce, "",
       "tau_R += value * sin(2 pi cycles_per_rad q + phase) (fields `cycles_per_rad`, `phase`)", Ripple},
      {kPassiveMoment, "relative", -1.0, 10.0, {}, S::kLink, C::kSubjectForce, "",
       "the subject's passive moment is 1 + value times Riener & Edrich 1999's (HJ15 eq. 12 as rebuilt, "
       "`model/passive_torque.h`): tau_R += value * P_j(q), whatever passive model the twin subtracts "
       "(optional field `cv`: see \"Realistic EXOwheel\")", Passive, nullptr, nullptr, nullptr,
       {{"cv", K::kOptionalField, 0.0, 2.0}}},  // cv: the inter-subject variation table5 draws from
      {kSensorOffset, "N m", -100.0, 100.0, {}, S::kSensor, C::kReading, "", "tau_S += value", nullptr,
       Offset, OffsetOff, OffsetAffine},
      {kSensorGain, "relative", -0.9, 10.0, {}, S::kSensor, C::kReading, "",
       "tau_S *= 1 + value (0.05 = reads 5 % high)", nullptr, Gain, GainOff, GainAffine},
      {kSensorDelay, "s", 0.0, 1.0, {}, S::kSensor, C::kReading, "", "tau_S(t) is the true reading at t - value",
       nullptr, Delay, DelayOff},
      {kMuscleActivity, "-", -1e6, 1e6, {}, S::kLink, C::kNotCarried, "",
       "the subject was not relaxed: residual explained by EMG envelopes", nullptr, nullptr, nullptr, nullptr,
       {{"weights", K::kWeights}, {"channels", K::kAccepted}}},
      {kTerm, "N m", -1e6, 1e6, {}, S::kLink, C::kAppliedForce, "",
       "tau_R += value * expr (field `expr`, \"Terms beyond the table\"); with `stage: sensor`, tau_S += value * "
       "expr", Term, nullptr, nullptr, nullptr, {}, true},
  };
  return k;
}

// DESIGN.md's families: the registry's size before anything is added.
size_t BuiltInFamilies() {
  static const size_t n = Registry().size();
  return n;
}

}  // namespace

const std::deque<EffectFamily>& EffectFamilies() { return Registry(); }

void AddEffectFamily(const EffectFamily& f) {
  if (!f.name || !*f.name || !f.unit || !*f.unit || !(f.lo < f.hi))
    throw std::invalid_argument("effect family: expected a name, a unit and lo < hi");
  if (FindFamily(f.name)) throw std::invalid_argument(std::string("effect family '") + f.name + "' exists");
  BuiltInFamilies();  // counted before the first addition
  Registry().push_back(f);
}

void RemoveAddedEffectFamily(const std::string& name) {
  if (Registry().size() <= BuiltInFamilies() || name != Registry().back().name)
    throw std::invalid_argument("effect family '" + name + "' is not the family added last");
  Registry().pop_back();
}

const EffectFamily* FindFamily(const std::string& name) {
  for (const EffectFamily& f : EffectFamilies())
    if (name == f.name) return &f;
  return nullptr;
}

const EffectFamily& FamilyOf(const Effect& e) {
  const EffectFamily* f = FindFamily(e.name);
  if (!f) throw std::invalid_argument("unknown effect family '" + e.name + "'");
  return *f;
}

std::string FamilyNames(bool (*keep)(const EffectFamily&)) {
  std::string s;
  for (const EffectFamily& f : EffectFamilies())
    if (!keep || keep(f)) s += (s.empty() ? "" : ", ") + std::string(f.name);
  return s;
}

int EffectJoint(const Effect& e) { return e.joint == "hip" ? 0 : 1; }

EffectStage StageOf(const Effect& e) {
  if (e.stage.empty()) return FamilyOf(e).stage;
  return e.stage == "sensor" ? EffectStage::kSensor : EffectStage::kLink;
}

TermSignals TermSignalsAt(const Effect& e, const EffectState& s) {
  const int j = EffectJoint(e);
  TermSignals x;
  x.q = s.q[j], x.qd = s.qd[j], x.qdd = s.qdd[j], x.tau_R = s.tau_R[j];
  x.q_hip = s.q[0], x.q_knee = s.q[1], x.qd_hip = s.qd[0], x.qd_knee = s.qd[1];
  x.t = s.t;
  return x;
}

Eigen::Vector2d GravityErrorTorque(const Effect& e, double g, const Eigen::Vector2d& q) {
  const int j = EffectJoint(e);
  const double ang = j == 0 ? q[0] : q[0] + q[1];
  const double dG = g * e.value * (e.axis == "Y" ? std::cos(ang) : std::sin(ang));
  return {dG, j == 1 ? dG : 0.0};
}

double TorqueRippleTorque(const Effect& e, double q_j) {
  return e.value * std::sin(2 * M_PI * e.fields.at("cycles_per_rad") * q_j + e.fields.at("phase"));
}

double PassiveMomentTorque(const Effect& e, const Eigen::Vector2d& q) {
  return e.value * PassiveElasticTorque(PassiveModel::kRiener1999, q)[EffectJoint(e)];
}

}  // namespace exotwin
