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
#pragma once
#include <deque>
#include <string>

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
};
struct MotionBox {
  double lo = 0, hi = 0, step = 0;
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
  // from the records' scales (MotionScale); nullptr: the family's own parameters (motion_candidates.cc).
  MotionBox (*motion_box)(const MotionScale& s) = nullptr;
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
