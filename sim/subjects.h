// Subjects of the twin: the 10 subjects of Hwang & Jeon 2015 (Tables 2-4) as named presets, and a
// seeded population of virtual subjects with the same statistics.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "model/lumped_params.h"

namespace exotwin {

struct Subject {
  std::string name;
  double age = 0;     // years
  double height = 0;  // m
  double weight = 0;  // kg
  double L1 = 0;      // thigh length, m
  double L2 = 0;      // lower-leg length, m
  LumpedParams human;  // HJ15 eq. 4, identified (Table 4) or drawn
  LumpedParams exo;    // HJ15 eq. 4, exoskeleton adjusted to this subject (Table 3) or drawn
};

// "S1".."S10": Table 2 characteristics, Table 4 identified human parameters (ground truth), Table 3
// exoskeleton. Throws InputError listing the valid names for any other name.
// Values are exactly as printed. S3's human parameters have no physically consistent realization
// (IsRealizable is false: (X2^2+Y2^2)/J2 = 6.07 kg > (J1-J2)/L1^2 = 5.95 kg; only the extreme corner
// of the printed rounding is feasible, with a thigh mass of thousands of kg), so a MuJoCo realization
// of S3 will be refused; the other nine and all ten exoskeleton sets are realizable.
Subject PresetSubject(const std::string& name);

// The preset names, "S1".."S10".
std::vector<std::string> PresetNames();

// Virtual subject number `index` (>= 0) of the population with seed `seed`; the same (seed, index)
// gives the same bits (the engine and the normal sampler do not depend on the standard library; only
// libm's log and Eigen's eigen-solver could differ in the last bit between toolchains). Each index
// is an independent draw (its own engine), so subject i does not depend on which others were drawn.
// Method (subjects.cc): multivariate normal over [W, L1, L2, J_H1..Y_H2] with the mean and
// covariance (divisor n, as Table 4's printed SD row) of the 10 paper subjects; exo, height and age
// drawn conditionally on L1, L2 (and W); draws without a physically consistent realization
// (IsRealizable) are rejected and redrawn (about 2 % are).
// Throws InputError if index < 0.
Subject DrawSubject(uint64_t seed, int index);

// The subject as a model file's contents (L1, exo, human; no passive torque, no effects).
LegParams SubjectLegParams(const Subject& s);

}  // namespace exotwin
