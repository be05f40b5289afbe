// Muscular torque estimate of Hwang & Jeon 2015 eq. (9)-(10): tau_M = tau_S - tau_PAS, with
// tau_PAS = -(M qdd + V + G + P) from the IDENTIFIED lumped parameters (model/leg_dynamics.h).
// Convention (DESIGN.md): hip flexion +, knee flexion -, tau_S = -tau_R the torque-sensor reading.
#pragma once
#include <vector>

#include <Eigen/Core>

#include "dsp/butterworth.h"
#include "model/lumped_params.h"

namespace exotwin {

// tau_PAS of eq. (10) (N m): minus the torque the relaxed combined system needs at (q, qd, qdd).
Eigen::Vector2d PassiveTorqueEstimate(const LegParams& identified, const Eigen::Vector2d& q,
                                      const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd);

// tau_M of eq. (9) (N m) from the sensor reading tau_S (N m) and the kinematics.
Eigen::Vector2d MuscularTorque(const LegParams& identified, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                               const Eigen::Vector2d& tau_S);

// Off-line estimate over a record sampled every dt (s): qd, qdd from q by a zero-phase 2nd-order
// Butterworth low-pass at fc (Hz, 20 Hz as the paper) and central differences, then eq. (9).
// q, tau_S: one Vector2d per sample, same length >= 8. Returns tau_M per sample.
std::vector<Eigen::Vector2d> MuscularTorqueOffline(const LegParams& identified,
                                                   const std::vector<Eigen::Vector2d>& q,
                                                   const std::vector<Eigen::Vector2d>& tau_S,
                                                   double dt, double fc = 20.0);

// Real-time estimator: causal 2nd-order 20 Hz low-pass of q, backward differences for qd and qdd
// (lag ~ 1.5 samples + filter delay; use the off-line variant for calibration). dt > 0.
class MuscularTorqueEstimator {
 public:
  MuscularTorqueEstimator(const LegParams& identified, double dt, double fc = 20.0);
  // One sample: measured q (rad) and tau_S (N m) -> tau_M (N m).
  Eigen::Vector2d Step(const Eigen::Vector2d& q, const Eigen::Vector2d& tau_S);

 private:
  LegParams params_;
  double dt_;
  dsp::SosFilter f_[2];
  Eigen::Vector2d q1_, q2_;
  int n_ = 0;
};

}  // namespace exotwin
