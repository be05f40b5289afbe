// Muscular torque estimate, HJ15 eq. 9-10 of Hwang & Jeon 2015: see muscular_torque.h.
#include "controller/muscular_torque.h"

#include "model/leg_dynamics.h"

namespace exotwin::controller {

Eigen::Vector2d PassiveTorqueEstimate(const LegParams& identified, const Eigen::Vector2d& q,
                                      const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  return -ActuatorTorque(identified, q, qd, qdd);  // HJ15 eq. 10: -(M qdd + V + G + P)
}

Eigen::Vector2d MuscularTorque(const LegParams& identified, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                               const Eigen::Vector2d& tau_S) {
  return tau_S - PassiveTorqueEstimate(identified, q, qd, qdd);  // HJ15 eq. 9
}

}  // namespace exotwin::controller
