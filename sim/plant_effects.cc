#include "sim/plant_effects.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "model/leg_dynamics.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

// The torque (N m) a kSubjectForce family needs at the human's angles q (its closed form; the
// velocities play no part in it).
Eigen::Vector2d SubjectTorque(const Effect& e, double g, const Eigen::Vector2d& q) {
  EffectState s;
  s.q = q, s.qd.setZero(), s.qdd.setZero(), s.g = g;
  return FamilyOf(e).link_torque(e, s);
}

}  // namespace

Eigen::Vector2d CompliantPartTorque(const LegParams& params, const Eigen::Vector2d& q,
                                    const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  if (!params.human) return ActuatorTorque(params, q, qd, qdd);
  Eigen::Vector2d tau = RigidInverseDynamics(*params.human, params.L1, params.g, q, qd, qdd) +
                        PassiveElasticTorque(params.passive, q);
  for (const Effect& e : params.effects)  // the subject's passive moment acts on the human's segments
    if (FamilyOf(e).carrier == PlantCarrier::kSubjectForce) tau += SubjectTorque(e, params.g, q);
  return tau;
}

Eigen::Vector2d CompliantAngle(const LegParams& params, int j, double k, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  // Newton on f(x) = x - q_j + tau_C,j(x)/k with a central-difference slope (1e-6 rad).
  Eigen::Vector2d qc = q;
  for (int it = 0; it < 6; ++it) {
    const double f = qc[j] - q[j] + CompliantPartTorque(params, qc, qd, qdd)[j] / k;
    Eigen::Vector2d a = qc, b = qc;
    a[j] += 1e-6;
    b[j] -= 1e-6;
    const double slope = 1.0 + (CompliantPartTorque(params, a, qd, qdd)[j] -
                                CompliantPartTorque(params, b, qd, qdd)[j]) / (2e-6 * k);
    const double step = f / std::max(slope, 0.1);  // a slope <= 0 would be a buckling strap
    qc[j] -= step;
    if (std::abs(step) < 1e-12) break;
  }
  return qc;
}

bool PlantEffects::link_empty() const {
  for (int j = 0; j < 2; ++j)
    if (frictionloss[j] != 0 || damping[j] != 0 || armature[j] != 0 || stiffness[j] != 0 || backlash[j] != 0 ||
        compliance[j] != 0)
      return false;
  return applied.empty() && friction_terms.empty();
}

Eigen::Vector2d PlantEffects::SubjectPassiveForce(const Eigen::Vector2d& q_follower) const {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (const Effect& e : applied)
    if (FamilyOf(e).carrier == PlantCarrier::kSubjectForce) f -= SubjectTorque(e, g, q_follower);
  return f;
}

bool PlantEffects::has_internal_joints() const {
  return backlash[0] != 0 || backlash[1] != 0 || compliance[0] != 0 || compliance[1] != 0;
}

bool PlantEffects::empty() const { return link_empty() && sensor[0].empty() && sensor[1].empty(); }

Eigen::Vector2d PlantEffects::AppliedForce(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                           const Eigen::Vector2d& qdd, const Eigen::Vector2d& tau_R, double t) const {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  EffectState s;
  s.q = q, s.qd = qd, s.qdd = qdd, s.g = g, s.tau_R = tau_R, s.t = t;
  for (const Effect& e : applied) {
    const EffectFamily& family = FamilyOf(e);
    if (family.carrier == PlantCarrier::kAppliedForce) f -= family.link_torque(e, s);
  }
  return f;
}

void PlantEffects::FrictionTermBounds(const EffectState& s, double bound[2], Eigen::Vector2d* force) const {
  bound[0] = bound[1] = 0;
  force->setZero();
  Effect at;  // the term's joint for its signals
  for (const FrictionTerm& ft : friction_terms) {
    at.joint = ft.joint == 0 ? "hip" : "knee";
    const double b = ft.value * ft.f.Eval(TermSignalsAt(at, s));
    if (b >= 0) bound[ft.joint] += b;
    else (*force)[ft.joint] -= b * CoulombSign(s.qd[ft.joint]);
  }
}

bool PlantEffects::has_friction_term(int j) const {
  for (const FrictionTerm& ft : friction_terms)
    if (ft.joint == j) return true;
  return false;
}

namespace {

// A term (DESIGN.md "Terms beyond the table"): at the sensor stage where the reading is formed; at the
// link a friction bound (friction-like) or an applied force.
void AddTerm(const Effect& e, int j, const std::string& where, PlantEffects* fx) {
  TermExpr expr;
  try {
    expr = TermExpr::Parse(e.expr);
  } catch (const TermExprError& x) {
    throw InputError(where + ": expr \"" + e.expr + "\": " + x.what() + " of the expression");
  }
  if (!std::isfinite(e.value)) throw InputError(where + ": value not finite");
  if (StageOf(e) == EffectStage::kSensor) {
    fx->sensor[j].push_back({e.name, e.value, e.expr});
    return;
  }
  FrictionTerm ft;
  ft.joint = j, ft.value = e.value;
  if (expr.FrictionLike(&ft.f)) fx->friction_terms.push_back(ft);
  else fx->applied.push_back(e);
}

// Smallest eigenvalue of M(th2) + diag(armature) over th2 in [-pi, pi) (360 points; M is periodic
// in th2, HJ15 eq. 5).
double SmallestInertiaEigenvalue(const LegParams& params, const double armature[2]) {
  const LumpedParams total = params.Total();
  double lo = INFINITY;
  for (int k = 0; k < 360; ++k) {
    Eigen::Matrix2d M = MassMatrix(total, params.L1, -M_PI + 2 * M_PI * k / 360.0);
    M(0, 0) += armature[0];
    M(1, 1) += armature[1];
    lo = std::min(lo, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(M, Eigen::EigenvaluesOnly).eigenvalues()[0]);
  }
  return lo;
}

}  // namespace

PlantEffects ToPlantEffects(const LegParams& params, const std::string& source) {
  PlantEffects fx;
  fx.g = params.g;
  fx.compliant_human = params.human.has_value();
  for (size_t i = 0; i < params.effects.size(); ++i) {
    const Effect& e = params.effects[i];
    const int j = e.joint == "hip" ? 0 : 1;
    const std::string where = source + ": effects[" + std::to_string(i) + "] (" + e.name + ", " + e.joint + ")";
    const EffectFamily* f = FindFamily(e.name);
    if (!f) throw InputError(where + ": unknown effect; expected one of " + FamilyNames());
    if (f->carries_expr) {
      AddTerm(e, j, where, &fx);
      continue;
    }
    switch (f->carrier) {
      case PlantCarrier::kFrictionLoss:
        if (e.value < 0) throw InputError(where + ": a negative Coulomb friction cannot be a MuJoCo frictionloss");
        fx.frictionloss[j] += e.value;
        break;
      case PlantCarrier::kDamping:
        fx.damping[j] += e.value;
        break;
      case PlantCarrier::kArmature:
        fx.armature[j] += e.value;
        break;
      case PlantCarrier::kSpring:
        if (fx.stiffness[j] != 0)
          throw InputError(where + ": a second " + e.name + " at this joint; the plant carries one spring per joint");
        fx.stiffness[j] = e.value;
        fx.springref[j] = e.fields.at("q0");
        break;
      case PlantCarrier::kAppliedForce:
        fx.applied.push_back(e);
        break;
      case PlantCarrier::kSubjectForce:
        if (params.one_joint)
          throw InputError(where + ": Riener & Edrich's curves are the two-joint leg's (hip and knee angles of HJ15); "
                           "a one-joint model cannot carry a " + e.name);
        if (!(e.value > -1 && e.value <= kMaxPassiveScale - 1))
          throw InputError(where + ": a passive moment " + std::to_string(1 + e.value) +
                           " times Riener & Edrich's; expected -1 < value <= " + std::to_string(kMaxPassiveScale - 1));
        fx.applied.push_back(e);
        break;
      case PlantCarrier::kReading:
        // The model file's range of the family (a gain above -1 reads a torque; a delay >= 0).
        if (!(e.value >= f->lo && e.value <= f->hi))
          throw InputError(where + ": " + std::to_string(e.value) + " " + f->unit + ", expected " +
                           std::to_string(f->lo) + " .. " + std::to_string(f->hi));
        fx.sensor[j].push_back({e.name, e.value});
        break;
      case PlantCarrier::kDeadBandHinge:
      case PlantCarrier::kStrapHinge:
        if (fx.backlash[j] != 0 || fx.compliance[j] != 0)
          throw InputError(where + ": a second internal hinge (backlash or series_compliance) at this joint; the "
                           "plant carries one internal hinge per joint");
        if (f->carrier == PlantCarrier::kDeadBandHinge) {
          if (!(e.value > 0 && e.value <= 0.1))
            throw InputError(where + ": a dead band of " + std::to_string(e.value) + " rad; expected 0 < value <= 0.1");
          fx.backlash[j] = e.value;
        } else {
          if (!(e.value > 0))
            throw InputError(where + ": a strap stiffness of " + std::to_string(e.value) + " N m/rad; expected > 0");
          if (j == 0 && params.human)
            throw InputError(where + ": the forward plant cannot carry a series compliance at the hip of a model "
                             "with a human (the human leg would turn about the hip while its knee follows the "
                             "exoskeleton's: a closed chain); carried at the knee, or at the hip without a human");
          fx.compliance[j] = e.value;
        }
        break;
      case PlantCarrier::kNotCarried:
        throw InputError(where + ": the forward plant cannot carry this effect (an input the record carries, such "
                         "as the subject's EMG, not a property of the plant); carried: " +
                         FamilyNames([](const EffectFamily& g) { return g.carrier != PlantCarrier::kNotCarried; }));
    }
  }
  for (int j = 0; j < 2; ++j)
    if (fx.damping[j] < 0 || fx.stiffness[j] < 0)
      throw InputError(source + ": the " + std::string(j == 0 ? "hip" : "knee") +
                       (fx.damping[j] < 0 ? "'s viscous friction" : "'s joint stiffness") +
                       " is negative: the plant would gain energy from it; expected >= 0");
  if (fx.armature[0] < 0 || fx.armature[1] < 0) {
    const double lo = SmallestInertiaEigenvalue(params, fx.armature);
    if (!(lo > 1e-6)) {
      std::ostringstream os;
      os << source << ": inertia_error " << fx.armature[0] << " / " << fx.armature[1]
         << " kg m^2 (hip / knee) leaves the inertia matrix with eigenvalue " << lo
         << " kg m^2 at some knee angle: the forward plant cannot carry it (expected M + diag(armature) "
            "positive definite)";
      throw InputError(os.str());
    }
  }
  return fx;
}

}  // namespace exotwin
