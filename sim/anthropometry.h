// Body-segment inertial parameters (BSIPs) from anthropometric models (Hwang & Jeon 2015, Table 1 and
// HJ15 eq. 11) and their lumped form (HJ15 eq. 4). The lower leg is shank + foot as one rigid segment
// (assumption 4 of the paper).
#pragma once
#include "model/lumped_params.h"

namespace exotwin {

// One segment: mass (kg); CM at a along the link from the proximal joint and b perpendicular to it
// (m, sign as in LumpedParams); Iz (kg m^2) about the CM, sagittal axis.
struct SegmentBsip {
  double mass = 0, a = 0, b = 0, Iz = 0;
};

// Thigh (hip to knee, length L1) and lower leg (knee to distal end, shank + foot).
struct LegBsip {
  SegmentBsip thigh, lower_leg;
  double L1 = 0;  // m
};

// HJ15 eq. 4: lumped J (kg m^2), X, Y (kg m) of a two-segment leg; m1, m2 carry the segment masses.
LumpedParams LumpFromBsip(const LegBsip& bsip);

enum class AnthropometricModel { kDeLeva, kDempster, kClauser };
const char* AnthropometricModelName(AnthropometricModel m);

// HJ15 eq. 11 with Table 1 as printed: m_i = W M_i, a_i = L_i CM_i, Iz_i = m_i (L_i RG_i)^2, b_i = 0.
// Lower leg = shank (length L2) + foot as a point mass at the distal end (distance L2 from the knee);
// the foot's own inertia is ignored (its RG refers to the foot length, which Table 2 does not give).
// weight_kg > 0, L1, L2 > 0 (m). Throws InputError on bad input and for kClauser (Table 1 gives no
// radius of gyration for Clauser, so there is no moment of inertia to compute).
LegBsip AnthropometricBsip(AnthropometricModel model, double weight_kg, double L1, double L2);

// The BSIPs behind Table 4's anthropometric columns, with the rule adopted in anthropometry.cc (the
// closest consistent rule found; Table 1 as printed does not reproduce those columns):
//   kDeLeva:   Table 1 De Leva row with the thigh CM of De Leva's own male table (40.95 %, not 45.5 %),
//              foot as a point mass at L2, foot inertia ignored;
//   kDempster: Dempster's table as adapted by Winter: thigh (10.0 %, 43.3 %, 32.3 %) and the
//              "Foot leg" row (shank + foot as one segment: 6.1 %, 60.6 %, RG 41.6 %) over L2.
// Same preconditions as AnthropometricBsip; kClauser throws InputError (Table 4 has no Clauser column).
LegBsip Table4RuleBsip(AnthropometricModel model, double weight_kg, double L1, double L2);

// LumpFromBsip(Table4RuleBsip(...)): Table-4-style anthropometric lumped parameters (Y = 0).
LumpedParams Table4AnthropometricLumped(AnthropometricModel model, double weight_kg, double L1,
                                        double L2);

}  // namespace exotwin
