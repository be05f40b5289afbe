// The embedding of a one-joint device (DESIGN.md "One-joint devices") in the two-link lumped model
// of HJ15 eq. 4, so that predict, diagnose, identify and generate confront it with the same code.
//
// With the hip held at q1 = 0 (qd1 = qdd1 = 0) the knee row of HJ15 eq. 5-7 is
//   tau_2 = J2 qdd2 + g (X2 sin q2 + Y2 cos q2),
// since M21 multiplies qdd1, the Coriolis and centrifugal terms of the knee row carry qd1, and
// G2 depends on q1 + q2 only. That is HKS05 eq. 4's link with I = J2, mgl = g X2, Y2 = 0, th = q2
// (HAL's convention: 0 hanging, positive extension, the knee convention of the twin's th2 too).
// R and C become the knee's viscous_friction and coulomb_friction effects. The hip's lumped values
// are those of a realizable thigh (1 kg at L1 / 2); the knee row does not depend on them.
#pragma once
#include <vector>

#include "model/lumped_params.h"

namespace exotwin {

// Thigh length of the embedding, m (any value in the model file's range: the knee row does not see it).
constexpr double kOneJointL1 = 0.41;

// LegParams of a one-joint model: the embedding described above, with R and C as the first effects
// followed by `effects` (knee effects of the model file). `g` in m/s^2.
LegParams EmbedOneJointModel(const OneJointModel& m, double g, const std::vector<Effect>& effects);

// The lumped two-link block of one one-joint link (I, mgl) at gravity g, with masses chosen so that it
// has a realization (m2 = max(2 X2^2 / J2, 0.1 kg), thigh 1 kg at L1 / 2).
LumpedParams OneJointLumped(const OneJointLink& link, double g);

}  // namespace exotwin
