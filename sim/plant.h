// The MuJoCo plant of the two-joint leg + exoskeleton (mjcf/leg_exowheel.xml or
// mjcf/exowheel_exo_only.xml) with the lumped parameters of a MODEL.yaml written into it.
// Immutable-after-setup model, mutable data; every physics call checks for divergence.
#pragma once
#include <memory>
#include <string>

#include <Eigen/Core>

#include "core/error.h"  // SimulationError, thrown by Plant
#include "model/lumped_params.h"
#include "sim/internal_joints.h"
#include "sim/plant_effects.h"
#include "sim/realization.h"

struct mjModel_;
struct mjData_;

namespace exotwin {

// Path of a model shipped in mjcf/ of the data folder (core/data_dir.h), e.g. "leg_exowheel.xml".
std::string ShippedModelPath(const std::string& file);

// The shipped EXOwheel model: leg_exowheel.xml (exoskeleton + human bodies) with a human, else
// exowheel_exo_only.xml (the exoskeleton alone).
std::string ExowheelMjcfPath(bool with_human);

// Writes the thigh length L1 (m) into one leg of `m` (the leg's names end in `suffix`, "" for the
// MJCF's own): body exo_shank<suffix> sits at z = -L1 in its parent, and the thigh geoms
// human_thigh_geom<suffix> and exo_thigh_bar<suffix> (those present; visual only) span 0..-L1. When
// a rotor body holds the knee hinge (sim/internal_joints.h), the rotor is placed there instead.
// Throws InputError if the model has no body exo_shank<suffix>. Call mj_setConst afterwards when
// the model simulates.
void SetThighLength(mjModel_* m, double L1, const std::string& suffix = "");

class Plant {
 public:
  // Loads an MJCF file with bodies exo_thigh, exo_shank (+ human_thigh, human_shank) and hinges
  // hip, knee. Throws InputError naming the file and MuJoCo's message if it cannot be used.
  explicit Plant(const std::string& mjcf_path);
  ~Plant();
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;

  // Writes L1, g and a consistent realization of params.exo / params.human into the model.
  // Throws InputError if a system has no realization or the model lacks human bodies.
  void SetParams(const LegParams& params);
  const LegParams& params() const { return params_; }
  bool has_human_bodies() const { return human_thigh_ >= 0; }

  // Carries the link-side effects of `fx` in the forward simulation (sim/plant_effects.h: MuJoCo's
  // frictionloss, damping, armature, stiffness/springref, and an applied force for gravity_error and
  // torque_ripple), replacing those carried before. Sensor effects are for the reader of tau_S.
  // Without effects (fx.link_empty()) the model is the MJCF's, bit for bit.
  // Backlash and series compliance rebuild the model with internal hinges (sim/internal_joints.h);
  // SetParams must have been called (the rotor's inertia comes out of the exoskeleton's segment).
  // Their numbers (sim/plant.cc): a rotor body of inertia kRotorInertiaFraction x the exoskeleton's J of that joint
  // (at least 4 k dt^2 behind a strap: its mode at most 0.5 / dt rad/s), taken out of the segment so
  // that with the internal hinge held the plant is the rigid one; a dead band's flanks are limit
  // constraints with MuJoCo's solref time constant 2 dt; a strap has stiffness k, springref 0 and
  // damping kStrapDampingRatio of its mode's critical value (sim/plant.cc). Throws InputError when the rotor cannot
  // be taken out of the segment (no realization left) or a strap's mode is too fast for the step;
  // after such a throw the plant is to be discarded.
  void CarryEffects(const PlantEffects& fx);
  const InternalJoints& internal_joints() const { return structure_; }
  // Internal hinge angle of joint j (rad; 0 without one): the followers' angle is q + internal_q.
  Eigen::Vector2d internal_q() const;
  double rotor_inertia(int j) const { return rotor_inertia_[j]; }
  const PlantEffects& effects() const { return fx_; }

  // Disables the joint limits and the actuators' ctrlrange clamp (replay of a foreign rig's record:
  // its joints turn beyond the EXOwheel's range and its motors beyond the EXOwheel's torque).
  void FreeJointsAndTorque();

  // Holds the hip at 0 in the forward simulation (a one-joint device embedded in the two-link model,
  // model/one_joint.h): the hip's dof gets the armature kHeldHipArmature, so that its acceleration
  // under any torque of the leg (|tau| < 1e3 N m) is below 1e-6 rad/s^2 and the knee row of
  // M qdd = tau - c - g is the knee's alone (M21 qdd1 ~ 1e-6 of M22 qdd2); after every step the hip's
  // angle and velocity are set back to 0. Reset ignores the hip's q and qd given. The knee then
  // follows HKS05 eq. 4: I qdd + mgl sin q = tau (+ the knee's carried effects).
  void HoldHip();
  bool hip_held() const { return hip_held_; }
  static constexpr double kHeldHipArmature = 1e9;  // kg m^2

  // Actuator torque tau_R (N m) for a relaxed subject: MuJoCo's rigid inverse dynamics (mj_inverse,
  // joint limits, frictionloss and carried effects excluded) plus the passive elastic torque P(q).
  // Does not change the simulation state.
  Eigen::Vector2d InverseDynamics(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                  const Eigen::Vector2d& qdd);

  // Sets the state (rad, rad/s) and time (s) of the forward simulation; recomputes kinematics.
  // q, qd are the measured (motor-side) joints. Internal hinges start at rest relative to their
  // joint: a dead band at the flank the rigid torque at q, qd and the acceleration `qdd` presses the
  // link against (the torque the link's motion needs, which the gear transmits in contact; the inverse
  // form's -value/2 tanh(tau / kBacklashTorqueWidth)), a strap at the deflection that carries the
  // part's rigid torque at q, qd and `qdd` (rad/s^2, when given, e.g. the measured one; else 0:
  // quasi-static), CompliantAngle.
  void Reset(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, double t = 0.0, const Eigen::Vector2d* qdd = nullptr);
  // Time (s) in which a strap's mode (sim/plant.cc: damped at kStrapDampingRatio of critical) decays
  // to 1 % of a start's error: 5 / (zeta omega), the slowest strap carried; 0 without a strap.
  double InternalSettlingTime() const;
  // Sets the measured (motor-side) joints' state (rad, rad/s) and the time (s); recomputes kinematics.
  // A strap keeps its deflection and deflection rate (its follower moves with the driven side); a dead
  // band's link keeps its angle and rate, pushed along by the flank it would pass. With Step, a motion of the measured joints prescribed step by step
  // (replay's run-in, diagnosis/replay.h), along which the internal hinges move by their dynamics.
  void Restate(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, double t);
  // Advances one physics step (model timestep) with actuator torque tau_R (N m) and an extra joint
  // torque tau_ext (N m, e.g. muscles or effects) acting on the link. Throws SimulationError on
  // divergence. P(q) is applied automatically when params.human is set, and the carried effects.
  // tau_ext and P act on the part behind an internal hinge (at the angles q + internal_q); the
  // carried table effects at the measured joints.
  void Step(const Eigen::Vector2d& tau_R, const Eigen::Vector2d& tau_ext = Eigen::Vector2d::Zero());

  Eigen::Vector2d q() const;
  Eigen::Vector2d qd() const;
  Eigen::Vector2d qdd() const;  // acceleration of the last step
  // The time (s) a term's t counts from (DESIGN.md "Terms beyond the table": the record's or run's
  // start); 0 unless set.
  void SetTermTimeOrigin(double t0) { term_t0_ = t0; }
  double time() const;
  double timestep() const;

  const mjModel_* model() const { return m_; }
  mjData_* data() { return d_; }

 private:
  void CheckDivergence(const char* where);
  int Body(const char* name, bool required) const;
  void BindModel();                               // ids, addresses and the MJCF's own per-dof values
  void Rebuild(const InternalJoints& structure);  // recompiles the MJCF with these internal hinges
  void WriteRealization(const LegParams& params); // bodies, L1, g (+ rotors); validates first
  void ApplyFreedom();

  std::string path_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  mjData_* d_inv_ = nullptr;  // scratch data for inverse dynamics
  int exo_thigh_ = -1, exo_shank_ = -1, human_thigh_ = -1, human_shank_ = -1;
  int hip_dof_ = -1, knee_dof_ = -1;
  LegParams params_;
  PlantEffects fx_;
  double term_t0_ = 0;
  Eigen::Vector2d last_qdd_ = Eigen::Vector2d::Zero();  // a term's qdd: the last step's acceleration (0 after a reset)
  // The MJCF's own per-dof values, which CarryEffects adds to.
  double base_frictionloss_[2] = {0, 0}, base_damping_[2] = {0, 0}, base_armature_[2] = {0, 0};
  double base_stiffness_[2] = {0, 0}, base_springref_[2] = {0, 0}, base_solref_[2] = {0, 0};
  int hip_jnt_ = -1, knee_jnt_ = -1;
  bool hip_held_ = false;
  int q_adr_[2] = {0, 1};              // qpos address of the measured hinges
  int in_jnt_[2] = {-1, -1}, in_q_[2] = {-1, -1}, in_v_[2] = {-1, -1}, rotor_body_[2] = {-1, -1};
  InternalJoints structure_;
  double rotor_inertia_[2] = {0, 0};
  double strap_omega_[2] = {0, 0};     // rad/s, a strap's undamped mode (0: none)
  bool has_params_ = false, free_ = false;
};

}  // namespace exotwin
