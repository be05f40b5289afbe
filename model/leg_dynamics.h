// Closed-form rigid-body dynamics of the two-segment leg, HJ15 eq. 5-7 of Hwang & Jeon 2015, coded
// independently of MuJoCo so that the two can be checked against each other.
//
// Convention (DESIGN.md): q = (th1 hip, th2 knee), th1 = 0 thigh hanging, flexion positive;
// th2 = 0 straight, flexion negative. Equation of motion (HJ15 eq. 3):
//   M(q) qdd + V(q, qd) + G(q) + P(q) = tau_M + tau_R,   torque sensor tau_S = -tau_R (HJ15 eq. 8).
#pragma once
#include <Eigen/Core>

#include "model/lumped_params.h"

namespace exotwin {

using Vec2 = Eigen::Vector2d;

// Inertia matrix M(q), HJ15 eq. 5. Only th2 enters. kg m^2.
Eigen::Matrix2d MassMatrix(const LumpedParams& p, double L1, double th2);

// Coriolis and centrifugal torques V(q, qd), HJ15 eq. 6. N m.
Vec2 CoriolisCentrifugal(const LumpedParams& p, double L1, const Vec2& q, const Vec2& qd);

// Gravitational torques G(q), HJ15 eq. 7. N m.
Vec2 GravityTorque(const LumpedParams& p, double g, const Vec2& q);

// Rigid inverse dynamics M qdd + V + G (no passive elastic torque). N m.
Vec2 RigidInverseDynamics(const LumpedParams& p, double L1, double g, const Vec2& q, const Vec2& qd,
                          const Vec2& qdd);

// Actuator torque tau_R the combined system needs when relaxed (tau_M = 0): M qdd + V + G + P, with
// P from params.passive. N m.
Vec2 ActuatorTorque(const LegParams& params, const Vec2& q, const Vec2& qd, const Vec2& qdd);

// Total mechanical energy T + V_grav of the combined system (J); for energy-balance tests.
double MechanicalEnergy(const LumpedParams& p, double L1, double g, const Vec2& q, const Vec2& qd);

}  // namespace exotwin
