// The effects of DESIGN.md "Effects" as the forward MuJoCo plant carries them, and the per-sample
// forms of the state-dependent ones (shared with the inverse form, diagnosis/effects.cc).
//
// Mapping onto MuJoCo's own model properties (Plant::CarryEffects):
//  - coulomb_friction  -> dof_frictionloss. MuJoCo's frictionloss is a soft constraint bounded by the
//    value: while the joint slides it resists with exactly value * sign(qd) (the table's form); near
//    qd = 0 it holds the joint (stiction) where the table's sign(qd) would chatter, and as the joint
//    decelerates towards a reversal it may already push the other way (it steers the velocity to
//    zero within its time constant). The time constant (dof_solref) is set to 2 physics steps, the
//    shortest MuJoCo integrates safely (its default 0.02 s widened the zone tenfold). Forward and
//    inverse agree to 2e-3 N m where |qd| > 0.1 rad/s (tests/diagnosis/replay_test.cc).
//  - viscous_friction  -> dof_damping (the passive force -value qd: exactly the table's form).
//  - inertia_error     -> dof_armature (value added to M_jj: the table's value * qdd). A negative
//    value is carried when M + diag(armature) stays positive definite at every knee angle (M depends
//    on the knee angle only), else refused (InputError).
//  - joint_stiffness   -> jnt_stiffness + qpos_spring (springref = q0): -value (q - q0), as the table.
//  - gravity_error     -> an applied generalized force (qfrc_applied) equal to minus the table's
//    torque, not a change of the segment's mass and centre of mass: a real mass change moves the
//    segment's inertia and its coupling terms (L1 X2 cos th2) too, which the effect's form (HJ15 eq. 7
//    with X or Y changed) does not carry; the applied force keeps forward and inverse one model.
//  - torque_ripple     -> an applied generalized force -value sin(2 pi k q + phase).
//  - passive_moment    -> an applied generalized force -value P_j(q) (PassiveMomentTorque): the subject's
//    passive moment off Riener & Edrich's population curves by the factor 1 + value. It is the human's,
//    as P^ itself: it acts where P^ acts (behind a strap, on the human's segments, at the human's
//    angles; SubjectPassiveForce), and the strap carries it (CompliantPartTorque).
//  - sensor_offset, sensor_gain, sensor_delay act where the reading tau_S is formed, not on the
//    link: PlantEffects::sensor holds them for that reader (diagnosis/replay.h inverts them).
//  - backlash and series_compliance: an internal hinge in the MJCF (Plant::CarryEffects rebuilds the
//    model, sim/internal_joints.h) between the driven, measured joint and the part behind it, which
//    the inverse forms below (diagnosis/effects.h) evaluate at the link angle:
//    backlash: a limited relative hinge of total width value (a hard dead band whose flanks are MuJoCo
//    limit constraints); the whole chain is behind it and the motor side is a rotor body.
//    series_compliance: a relative hinge with stiffness value, springref 0: behind it the human limb
//    (a model with a human, at the knee) or the whole chain (no human, behind a rotor body).
//  - term (DESIGN.md "Terms beyond the table"): at the link stage an applied generalized force
//    -value * expr each step from the state and the actuator torque applied at that step; a
//    friction-like one (expr = f sgn(qd), TermExpr::FrictionLike) instead that step's friction bound
//    dof_frictionloss += value * f (an applied force where value * f < 0: no bound pushes along the
//    motion). At the sensor stage it acts where the reading is formed (SensorEffect::expr).
//  - muscle_activity: not carried (the subject's EMG is an input of the record, not a property of the
//    plant): ToPlantEffects refuses it (InputError).
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "model/effect_families.h"  // the families' closed forms (GravityErrorTorque, ...)
#include "model/lumped_params.h"
#include "model/term_expr.h"

namespace exotwin {

// Torque-sensor effects of one joint, in the order the model file lists them (DESIGN.md: tau_S +=
// offset, tau_S *= 1 + gain, tau_S(t) = true reading at t - delay).
struct SensorEffect {
  std::string name;  // sensor_offset | sensor_gain | sensor_delay | term
  double value = 0;
  std::string expr;  // a sensor-stage term's: tau_S += value * expr
  bool operator==(const SensorEffect& o) const { return name == o.name && value == o.value && expr == o.expr; }
};

// A friction-like link term at a joint: the friction bound value * f each step (f the factor of
// expr = f sgn(qd)).
struct FrictionTerm {
  int joint = 0;
  double value = 0;
  TermExpr f;
};

// Transition width of the backlash flank selection s(tau) = tanh(tau / width), N m (the inverse form:
// diagnosis/effects.h).
constexpr double kBacklashTorqueWidth = 0.1;

// Torque (N m) the series-compliant part needs: human rigid dynamics + P(q) when params.human,
// else the whole chain's actuator torque (HJ15 eq. 5-7).
Eigen::Vector2d CompliantPartTorque(const LegParams& params, const Eigen::Vector2d& q,
                                    const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd);

// Link angle of joint j under a strap of stiffness k (N m/rad): solves q_c,j = q_j - tau_C,j(q_c)/k
// (quasi-static: the deflection's own rates neglected).
Eigen::Vector2d CompliantAngle(const LegParams& params, int j, double k, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd);

struct PlantEffects {
  double frictionloss[2] = {0, 0};  // N m
  double damping[2] = {0, 0};       // N m s/rad
  double armature[2] = {0, 0};      // kg m^2
  double stiffness[2] = {0, 0};     // N m/rad
  double springref[2] = {0, 0};     // rad
  double backlash[2] = {0, 0};      // rad, total dead-band width (0: none)
  double compliance[2] = {0, 0};    // N m/rad, strap stiffness (0: none)
  bool compliant_human = false;     // the part behind a strap is the human limb (else the whole chain)
  std::vector<Effect> applied;      // kAppliedForce and kSubjectForce families: qfrc_applied each step
  std::vector<FrictionTerm> friction_terms;  // friction-like link terms: frictionloss each step
  std::vector<SensorEffect> sensor[2];
  double g = 9.81;                  // for gravity_error
  bool empty() const;
  bool link_empty() const;          // no effect on the link (only sensor effects, or none)
  bool has_internal_joints() const; // backlash or series_compliance: the MJCF gains hinges
  // The generalized force (N m) of `applied` at (q, qd): minus the torques the actuator needs for the
  // families carried as an applied force (PlantCarrier::kAppliedForce), each by its own closed form;
  // those carried at the human's angles (kSubjectForce) are SubjectPassiveForce's. A term also reads
  // qdd, the actuator torque tau_R and the time t (s from the run's or record's start).
  Eigen::Vector2d AppliedForce(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                               const Eigen::Vector2d& qdd = Eigen::Vector2d::Zero(),
                               const Eigen::Vector2d& tau_R = Eigen::Vector2d::Zero(), double t = 0) const;
  // The friction-like terms at state s: bound[j] (N m) to add to joint j's frictionloss, and the
  // applied force (N m) of those whose bound value * f is negative (-value * f sgn(qd)).
  void FrictionTermBounds(const EffectState& s, double bound[2], Eigen::Vector2d* force) const;
  bool has_friction_term(int j) const;
  // The generalized force (N m) of the passive_moment effects of `applied` at the human's angles
  // q_follower (behind a strap or dead band: q + the internal hinges' angles): where Riener & Edrich's
  // P^ acts, on the human's segments.
  Eigen::Vector2d SubjectPassiveForce(const Eigen::Vector2d& q_follower) const;
};

// Sorts `params.effects` into the plant's form (a term by its stage and TermExpr::FrictionLike).
// Throws InputError naming `source`, the effect
// (effects[i], its name and joint) and why, for an effect the plant cannot carry (muscle_activity;
// series_compliance at the hip of a model with a human; a second backlash or compliance at one joint;
// a backlash outside 0 .. 0.1 rad or a stiffness <= 0) and for a negative inertia_error that leaves M + diag(armature)
// not positive definite at some knee angle (checked on the closed form, HJ15 eq. 5).
PlantEffects ToPlantEffects(const LegParams& params, const std::string& source);

}  // namespace exotwin
