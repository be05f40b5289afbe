// The effect families of DESIGN.md "Effects": one registry that every stage iterates instead of
// branching on an effect's name. A family's row holds what every layer needs of it: its identity
// (name, unit, the model file's range and fields, link or sensor stage), how the forward plant carries
// it (PlantCarrier), which families exclude each other at one joint (exclusive group), the table's
// words (DESIGN.md's effect table is checked against them, tests/model/effect_families_test.cc) and
// its closed forms where they are a function of one sample's state:
//  - link_torque: the torque (N m) the actuator needs in addition at both joints, DESIGN.md's form;
//  - on_reading: the sensor effect on the reading tau_S of its joint (a whole series: the delay needs
//    the record's times).
// Families whose form needs more than one sample's state (backlash and series_compliance: the rigid
// torque and the compliant part's; muscle_activity: the record's EMG envelopes) have no link_torque;
// their forms live with the code that has those inputs (diagnosis/effects.cc), named by carrier.
// This is the model layer: the fit's behaviour of a family (its columns, physical ranges against the
// records) sits in diagnosis/, found there by the family's name.
#pragma once
#include <deque>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "model/lumped_params.h"
#include "model/term_expr.h"

namespace exotwin {

// Where the forward MuJoCo plant carries a family (sim/plant_effects.h, DESIGN.md "Effects in the
// forward plant").
enum class PlantCarrier {
  kFrictionLoss,   // dof_frictionloss (Coulomb friction)
  kDamping,        // dof_damping
  kArmature,       // dof_armature
  kSpring,         // jnt_stiffness + qpos_spring (field q0)
  kAppliedForce,   // qfrc_applied = -link_torque at the measured angles each step
  kSubjectForce,   // qfrc_applied = -link_torque at the human's angles (behind a strap or dead band)
  kDeadBandHinge,  // an internal hinge limited to +-value/2 (sim/internal_joints.h)
  kStrapHinge,     // an internal hinge with stiffness value (sim/internal_joints.h)
  kReading,        // where the reading tau_S is formed (not on the link)
  kNotCarried,     // an input of the record, not a property of the plant (EMG)
};

enum class EffectStage { kLink, kSensor };

// One sample's state for a closed form: angles, velocities, accelerations (rad, rad/s, rad/s^2; [0]
// hip, [1] knee) and gravity (m/s^2); for a term (model/term_expr.h) also the actuator torque tau_R
// (N m: the rigid twin's where the motion is given, the one applied at that step in the forward plant)
// and the time t (s from the record's or run's start).
struct EffectState {
  Eigen::Vector2d q, qd, qdd;
  double g = 9.81;
  Eigen::Vector2d tau_R = Eigen::Vector2d::Zero();
  double t = 0;
};

// DESIGN.md's families by name, for code that constructs a named effect (a device's own friction, a
// bench's hidden effect, an identification's result): each name spelled once, in the registry's row.
extern const char* const kCoulombFriction;
extern const char* const kViscousFriction;
extern const char* const kInertiaError;
extern const char* const kGravityError;
extern const char* const kJointStiffness;
extern const char* const kBacklash;
extern const char* const kSeriesCompliance;
extern const char* const kTorqueRipple;
extern const char* const kPassiveMoment;
extern const char* const kSensorOffset;
extern const char* const kSensorGain;
extern const char* const kSensorDelay;
extern const char* const kMuscleActivity;
extern const char* const kTerm;

// A model-file key of a family beyond name, joint, value, unit and its required `fields`; the reader
// (formats/model_file.cc) reads it by kind, the writer writes the effect's axis, fields and weights.
struct EffectKey {
  enum class Kind {
    kAxis,           // Effect::axis: X or Y (default X)
    kOptionalField,  // a number in [lo, hi] into fields[key] where given
    kWeights,        // a mapping EMG channel -> N m per V into fields["w_" + channel]
    kAccepted,       // accepted and ignored (written by other tools)
  };
  const char* key;
  Kind kind;
  double lo = 0, hi = 0;
};

struct EffectFamily {
  const char* name;
  const char* unit;
  double lo, hi;                    // the model file's accepted values (physical sense, not the fit's range)
  std::vector<std::string> fields;  // required numeric fields (e.g. q0)
  EffectStage stage;
  PlantCarrier carrier;
  const char* exclusive;            // families of one group exclude each other at one joint ("" none)
  const char* table;                // DESIGN.md's "what the rig does that the rigid twin does not"
  // Torque (N m) the actuator needs in addition at both joints; nullptr where one sample's state
  // does not determine it.
  Eigen::Vector2d (*link_torque)(const Effect& e, const EffectState& s) = nullptr;
  // Applies a sensor family to its joint's reading tau_S (samples at times t); nullptr for link families.
  void (*on_reading)(const Effect& e, const std::vector<double>& t, std::vector<double>* tau_S) = nullptr;
  // Its inverse: the reading before the effect from the reading after it (replay's actuator torque).
  void (*off_reading)(double value, const std::vector<double>& t, std::vector<double>* tau_S) = nullptr;
  // A sensor family that is affine in the torque: the reading a tau + b becomes a' tau + b'
  // (a joint module's gain and offset); nullptr for the delay (whole samples of the module's skew).
  void (*affine)(double value, double* a, double* b) = nullptr;
  std::vector<EffectKey> keys;  // its model-file keys beyond `fields`
  // A term (DESIGN.md "Terms beyond the table"): each effect carries its own `expr` (model/term_expr.h)
  // and may carry a `stage` (link or sensor); link_torque is value * expr at the joint.
  bool carries_expr = false;
};

// Every family: DESIGN.md's table in its order, then any added by AddEffectFamily. References stay
// valid as families are added.
const std::deque<EffectFamily>& EffectFamilies();

// Adds a family to the registry (a device's own effect, a test's toy family): every stage then
// iterates it. Call before any stage runs (the registry is not locked). Throws std::invalid_argument
// for a name already taken, an empty name or unit, or lo >= hi.
void AddEffectFamily(const EffectFamily& f);
// Removes the family added last, which must be `name` (a test's toy family, when the test ends);
// throws std::invalid_argument otherwise (DESIGN.md's families are never removed).
void RemoveAddedEffectFamily(const std::string& name);

// The family of `name`; nullptr for an unknown name.
const EffectFamily* FindFamily(const std::string& name);

// The family of an effect; throws std::invalid_argument for an unknown name (a model file's reader
// refuses those first, with InputError).
const EffectFamily& FamilyOf(const Effect& e);

// The names of the families for which `keep` holds (nullptr: every family), joined by ", " (messages).
std::string FamilyNames(bool (*keep)(const EffectFamily&) = nullptr);

// The sign of coulomb_friction's closed form (and of a term's sgn): +-1, 0 at 0.
inline double CoulombSign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// The stage an effect acts at: its own `stage` ("link" or "sensor", a term's) or its family's.
EffectStage StageOf(const Effect& e);

// A term's signals (model/term_expr.h) at its joint from one sample's state.
TermSignals TermSignalsAt(const Effect& e, const EffectState& s);

// Joint index of an effect ("hip" -> 0, "knee" -> 1).
int EffectJoint(const Effect& e);

// The closed forms shared with the fit's columns and the forward plant:
// gravity_error: the lumped X (or Y) of the segment distal to the effect's joint off by e.value,
// HJ15 eq. 7 (thigh: the hip row only; lower leg: both rows, at the absolute angle th1 + th2).
Eigen::Vector2d GravityErrorTorque(const Effect& e, double g, const Eigen::Vector2d& q);
// torque_ripple (fields cycles_per_rad, phase): value sin(2 pi cycles_per_rad q_j + phase).
double TorqueRippleTorque(const Effect& e, double q_j);
// passive_moment: value P_j(q), P the passive elastic torque of Riener & Edrich 1999
// (model/passive_torque.h; HJ15 eq. 1, 12), whatever passive model the twin itself subtracts.
double PassiveMomentTorque(const Effect& e, const Eigen::Vector2d& q);

}  // namespace exotwin
