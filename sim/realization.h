// A physically consistent set of rigid bodies for lumped parameters (HJ15 eq. 4): the inverse of the
// lumping, used to write MODEL.yaml values into the MuJoCo model at run time.
#pragma once
#include <string>

#include "model/lumped_params.h"

namespace exotwin {

// One rigid segment in its joint frame: mass (kg), centre of mass a along the link towards the distal
// end and b perpendicular (m, see LumpedParams), sagittal moment of inertia about the CM Iz (kg m^2).
struct SegmentInertial {
  double mass = 0, a = 0, b = 0, Iz = 0;
};

struct SystemRealization {
  SegmentInertial thigh, lower_leg;
};

// Chooses masses and returns segments whose HJ15 eq. 4 lumping reproduces p exactly, with every mass and
// Iz > 0. Rule (documented in the .cc): m2 = p.m2 if given, else the middle of its feasible window;
// m1 = p.m1 if given, else 1.25 x its lower bound. Throws InputError naming `what` (e.g. "human")
// and the violated condition when no consistent realization exists or a given mass is infeasible.
SystemRealization RealizeLumped(const LumpedParams& p, double L1, const std::string& what);

// HJ15 eq. 4 applied to a realization (the forward lumping), for checks.
LumpedParams LumpRealization(const SystemRealization& r, double L1);

}  // namespace exotwin
