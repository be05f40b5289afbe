// Whether lumped parameters (HJ15 eq. 4) of one system have a physically consistent realization.
#pragma once
#include <string>

#include "model/lumped_params.h"

namespace exotwin {

// True iff there are masses m1, m2 > 0, CM offsets a_i, b_i and Iz1, Iz2 > 0 whose HJ15 eq. 4 lumping
// is p for thigh length L1 (m). Condition: J2 > 0 and m2's window
//   (X2^2 + Y2^2)/J2 < m2 < (J1 - J2)/L1^2
// is not empty (then any m1 > ((X1 - m2 L1)^2 + Y1^2)/(J1 - J2 - m2 L1^2) works). p.m1/p.m2 hints are
// ignored. Non-finite values or L1 <= 0 give false. When false and why != nullptr, *why says which
// condition failed, with the numbers. Pure function.
bool IsRealizable(const LumpedParams& p, double L1, std::string* why = nullptr);

}  // namespace exotwin
