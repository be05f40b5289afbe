// The effect families' behaviour in the torque fit and in `generate` (the diagnosis layer's half of
// the registry; the model layer's half, identity and closed forms, is model/effect_families.h). One
// row per family, found by the family's name; the stages (diagnose_select.cc, diagnose.cc,
// generate.cc) iterate these rows instead of branching on names:
//  - implausible: why a fitted value lies outside DESIGN.md's physical range (empty: inside);
//  - range_edge: the largest magnitude that range allows a one-parameter candidate (0: unbounded);
//  - to_effect: the effect, its interval and fields from the candidate's fitted coefficients (the
//    default: value = the first column's coefficient, +-1.96 standard errors);
//  - significant: the candidate is significant in the fit (the default: |first coefficient| > kMinT se);
//  - ceiling_sign: +1 where the black-box-free ceiling's fit holds the first coefficient >= 0;
//  - refined_on_exact_form: the fit's column is first order in the value (backlash, strap, delay):
//    the value is refined on the exact form after the linear fit;
//  - draw: generate's hidden effect at a joint with a realistic magnitude (nullptr: not drawn).
// A family linear in its value needs no code of its own (linear_column, motion_box); the others' rows
// hold their own code as hooks (add_columns, motion_candidates, ...), each family's rows and hooks in
// its file (family_rows.h lists them), so a reader finds a family in one place by its name.
#pragma once
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/rng.h"
#include "diagnosis/diagnose_columns.h"
#include "diagnosis/diagnose_select.h"
#include "model/effect_families.h"

namespace exotwin {

// The records' scales at one joint the motion fit's boxes are set from: the largest measured torque
// (N m), the twin's mean diagonal inertia (kg m^2), the RMS velocity (rad/s) and DESIGN.md's gravity
// edge (kg m).
struct MotionScale {
  double tau = 0, M = 0, qd_rms = 0, grav = 0;
  double q_rms = 0;  // rad, the angle's RMS about its mean
  double range = 0;  // rad, the recorded angle's range
  double tau_C = 0;  // N m, the largest torque the compliant part carries
};
struct MotionBox {
  double lo = 0, hi = 0, step = 0;
};

struct ColumnContext;  // diagnosis/column_tools.h
class MotionProblem;   // diagnosis/motion_fit.h
struct FitFamily;

// What a family's motion-fit candidates (FitFamily::motion_candidates) see of the problem at joint j
// (MotionProblem::AddCandidates).
struct MotionJoint {
  int j = 0;
  const LegParams* params = nullptr;
  MotionScale scale;
  int constant = -1;           // the joint's constant input torque parameter (the stiffness's k q0)
  bool reading_input = false;  // every record driven by its torque reading (the sensor families)
  const std::vector<DiagnosedEffect>* torque_named = nullptr;  // the torque fit's effects
  // A parameter of family f at j, its box and secant step; `kind` names it (MotionProblem::kind), f a
  // frequency it carries (Candidate::ripple_f). Returns its index.
  std::function<int(const FitFamily& f, const std::string& kind, MotionBox box, double freq)> add_parameter;
  std::function<void(const FitFamily& f, std::vector<int> parameters)> add_candidate;
  // The model given carries f, or a family of its exclusive group, at j: no candidate.
  std::function<bool(const FitFamily& f)> carried;
  // Parameter k's value stands for family f's effect (EffectsOf; the constant parameter's owner).
  std::function<void(int k, const FitFamily& f)> own;
};

struct FitFamily {
  const EffectFamily* family = nullptr;
  std::string (*implausible)(const Effect& e, const PhysicalScale& s) = nullptr;
  double (*range_edge)(int j, const PhysicalScale& s) = nullptr;
  void (*to_effect)(const Candidate& c, const Fit& f, DiagnosedEffect* d) = nullptr;
  bool (*significant)(const Candidate& c, const Fit& f) = nullptr;
  int ceiling_sign = 0;
  bool refined_on_exact_form = false;
  Effect (*draw)(Rng& rng, int joint, bool one_joint) = nullptr;
  // The torque fit's column is the family's closed form at value 1 (a family linear in its value:
  // Delta tau_S = -value link_torque(value 1)), one candidate per entry of `axes` (none: one).
  bool linear_column = false;
  std::vector<std::string> axes;
  // A candidate only for such models (nullptr: every model).
  bool (*candidate_for)(const LegParams& params) = nullptr;
  // The motion fit's parameter of a family linear in its value: its box and secant step at a joint
  // from the records' scales (MotionScale); nullptr: the family's own (motion_candidates below) or none.
  MotionBox (*motion_box)(const MotionScale& s) = nullptr;

  // ---- a family with its own code (its file, diagnosis/family_*.cc) --------------------------------
  // The torque fit's candidates and columns at one joint where they are not its closed form at value 1
  // (BuildColumns: after the linear families, in the registry's order).
  void (*add_columns)(ColumnContext& ctx, const FitFamily& self) = nullptr;
  // Candidates whose columns are searched on a target (AddSearchedCandidates: the ripple's frequency).
  void (*add_searched_columns)(std::vector<ColumnBank>& banks, const std::vector<const Kinematics*>& kins,
                               const std::vector<Eigen::VectorXd>& targets, const FitFamily& self) = nullptr;
  // A column first order in the value, evaluated again as the secant at the value d the first-order
  // column fits (the torque fit's stage 3b): *v the column's values at the candidate's joint on every
  // sample of the record (kin; tau_S_j the twin's reading there); false where d is not taken.
  bool (*secant_column)(double d, const Kinematics& kin, const std::vector<double>& tau_S_j,
                        std::vector<double>* v) = nullptr;
  // The motion fit's candidates at one joint (with motion_box: generic).
  void (*motion_candidates)(MotionJoint& mj, const FitFamily& self) = nullptr;
  // The effect parameter k of the family stands for at theta (theta[k] != 0; *e named, at its joint,
  // with value theta[k]); false: none.
  bool (*motion_effect)(const MotionProblem& P, int k, const Eigen::VectorXd& theta, Effect* e) = nullptr;
  // The torque fit's effect as its motion candidate's parameter values (nullptr: the first parameter
  // takes the value).
  void (*torque_values)(const Effect& e, const Candidate& cand, Eigen::VectorXd* theta) = nullptr;
  // Why the motion fit has no candidate for e, where the family knows ("" where it does not).
  std::string (*no_motion_candidate)(const Effect& e, const LegParams& params) = nullptr;
  // The motion fit's exchange of forms (a friction's: Coulomb for viscous and back): the family tried
  // in its place, from the torque the value gives at the joint's RMS speed and its inverse.
  const char* exchanged_with = nullptr;
  double (*torque_at_speed)(double value, double qd_rms) = nullptr;
  double (*value_at_speed)(double torque, double qd_rms) = nullptr;
  // A reading of the named effect e that the data of a moving joint cannot tell apart from it, given
  // the other named effects (e.g. a sensor offset beside a Coulomb friction: a direction-dependent
  // friction), as an alias whose effects stand in e's place; false: none.
  bool (*equivalent)(const DiagnosedEffect& e, const std::vector<DiagnosedEffect>& named, EffectAlias* a) = nullptr;
};

// Every family's fit row: DESIGN.md's families in the model registry's order, then those added.
const std::deque<FitFamily>& FitFamilies();

// Adds the fit row of a family added to the model registry (AddEffectFamily); before any stage runs.
// Throws std::invalid_argument for a row without a model family or implausible check, or a family
// that has a row.
void AddFitFamily(const FitFamily& f);
// Removes the fit row added last, which must be the family `name`'s (RemoveAddedEffectFamily's partner).
void RemoveAddedFitFamily(const std::string& name);

// The fit row of the family `name`; throws std::invalid_argument for a name of no family.
const FitFamily& FitFamilyOf(const std::string& name);
// The same, nullptr for a name of no family.
const FitFamily* FindFitFamily(const std::string& name);

}  // namespace exotwin
