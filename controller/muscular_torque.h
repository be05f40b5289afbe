// Muscular torque estimate of HJ15 eq. 9-10: tau_M = tau_S - tau_PAS, with
// tau_PAS = -(M qdd + V + G + P) from the IDENTIFIED lumped parameters (model/leg_dynamics.h).
// Convention (DESIGN.md): hip flexion +, knee flexion -, tau_S = -tau_R the torque-sensor reading.
// qd, qdd are the caller's: off line, dsp::ZeroPhaseDerivatives (the paper's zero-phase 20 Hz
// Butterworth and central differences, as analysis' DeriveKinematics).
#pragma once
#include <Eigen/Core>

#include "model/lumped_params.h"

namespace exotwin::controller {

// tau_PAS of HJ15 eq. 10 (N m): minus the torque the relaxed combined system needs at (q, qd, qdd).
Eigen::Vector2d PassiveTorqueEstimate(const LegParams& identified, const Eigen::Vector2d& q,
                                      const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd);

// tau_M of HJ15 eq. 9 (N m) from the sensor reading tau_S (N m) and the kinematics (rad, rad/s, rad/s^2).
Eigen::Vector2d MuscularTorque(const LegParams& identified, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                               const Eigen::Vector2d& tau_S);

}  // namespace exotwin::controller
