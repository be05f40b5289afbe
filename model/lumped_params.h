// Lumped inertial parameters of the two-segment sagittal leg model of Hwang & Jeon 2015, HJ15 eq. 4,
// and the model-file contents built on them (DESIGN.md "Model parameter file").
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace exotwin {

// Lumped parameters of one system (exoskeleton R or human H), HJ15 eq. 4:
//   J1 = Iz1 + Iz2 + m1 (a1^2 + b1^2) + m2 (a2^2 + b2^2) + m2 L1^2   [kg m^2]
//   J2 = Iz2 + m2 (a2^2 + b2^2)                                      [kg m^2]
//   X1 = m1 a1 + m2 L1,  X2 = m2 a2                                   [kg m]
//   Y1 = m1 b1,          Y2 = m2 b2                                   [kg m]
// a_i along the link (towards the distal end), b_i perpendicular to it, positive forward when the
// segment hangs (i.e. the link direction rotated by +90 deg in the direction of positive theta).
struct LumpedParams {
  double J1 = 0, J2 = 0, X1 = 0, X2 = 0, Y1 = 0, Y2 = 0;
  // Optional segment masses (kg) the MuJoCo realization should use (thigh, lower leg); <= 0: choose.
  double m1 = 0, m2 = 0;
};

// Sum of two systems' lumped parameters (the combined human-exoskeleton system, HJ15 eq. 3).
LumpedParams operator+(const LumpedParams& a, const LumpedParams& b);

enum class PassiveModel { kNone, kRiener1999 };
const char* PassiveModelName(PassiveModel m);

// A model extension (DESIGN.md "Effects"): what the rig does that the rigid twin does not.
struct Effect {
  std::string name;   // coulomb_friction, viscous_friction, ... (see DESIGN.md)
  std::string joint;  // "hip" or "knee"
  double value = 0;
  std::string unit;
  std::map<std::string, double> fields;  // q0, cycles_per_rad, phase, ...
  std::string axis;                      // gravity_error only: "X" or "Y"
  std::string expr{};                    // term only: value * expr (model/term_expr.h's grammar)
  std::string stage{};                   // "" (the family's), "link" or "sensor" (term only)
};

// A one-joint device (DESIGN.md "One-joint devices"): HAL-3's knee model of Lee & Sankai, HKS05
// eq. 4 (sigma = 0, no muscle torque): I thdd + R thd + C sgn(thd) + mgl sin th = tau, th = 0 hanging,
// positive extension. I and mgl are the device's link (frame, cuff and the motor's armature) plus the
// operator's lower leg when present; R, C the device's viscous and Coulomb friction.
struct OneJointLink {
  double I = 0;    // kg m^2 about the joint
  double mgl = 0;  // N m, gravity moment amplitude
};
struct OneJointModel {
  OneJointLink device;
  std::optional<OneJointLink> human;  // the operator's lower leg; absent = the device alone
  double R = 0, C = 0;                // N m s/rad, N m (>= 0)
  // Leading entries of LegParams::effects that stand for R and C (viscous_friction, coulomb_friction
  // at the knee, in that order, each present when non-zero).
  size_t device_effects = 0;
};

// Everything a MODEL.yaml holds.
struct LegParams {
  double L1 = 0.41;                   // thigh length (hip to knee), m
  double g = 9.81;                    // gravitational acceleration, m/s^2
  LumpedParams exo;                   // exoskeleton (R)
  std::optional<LumpedParams> human;  // human limb (H); absent = exoskeleton alone
  PassiveModel passive = PassiveModel::kNone;
  std::vector<Effect> effects;
  // A one-joint model file: its values. The fields above then hold its embedding in the two-link
  // model (model/one_joint.h): the joint as the knee, the hip held at 0.
  std::optional<OneJointModel> one_joint;

  // Combined lumped parameters (exo + human when present): the HR system of HJ15 eq. 3.
  LumpedParams Total() const;
};

}  // namespace exotwin
