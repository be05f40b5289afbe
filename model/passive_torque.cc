#include "model/passive_torque.h"

#include <cmath>

#include "core/units.h"

namespace exotwin {

// The original law (Riener & Edrich 1999), angles in degrees, each moment positive in the direction of
// its angle (hip flexion, knee flexion, ankle plantarflexion):
//   M_H = exp(1.4655 - 0.0034 K - 0.0750 H) - exp(1.3403 - 0.0226 K + 0.0305 H) + 8.072
//   M_K = exp(1.800 - 0.0460 A - 0.0352 K + 0.0217 H) - exp(-3.971 - 0.0004 A + 0.0495 K - 0.0128 H)
//         + exp(2.220 - 0.150 K) - 4.820
// HJ15 eq. 12 of Hwang & Jeon 2015 converted these to radians as if th2 were flexion-positive (it is
// flexion-negative), flipped P2's overall sign and mixed the coefficients of the second knee
// exponential (its "0.73 th2 - 0.0128 th1" should read "-2.836 th2 - 0.733 th1" in its own
// convention). We do not use HJ15 eq. 12: we map the conventions explicitly,
//   H = deg(th1),  K = -deg(th2),  A = 0,
// and, since the moment M_H acts along +th1 and M_K along -th2 (knee flexion = negative th2),
//   P1 = -M_H,  P2 = -(-M_K) = +M_K.
double RienerHipMoment(double H, double K) {
  return std::exp(1.4655 - 0.0034 * K - 0.0750 * H) - std::exp(1.3403 - 0.0226 * K + 0.0305 * H) +
         8.072;
}

double RienerKneeMoment(double A, double K, double H) {
  return std::exp(1.800 - 0.0460 * A - 0.0352 * K + 0.0217 * H) -
         std::exp(-3.971 - 0.0004 * A + 0.0495 * K - 0.0128 * H) + std::exp(2.220 - 0.150 * K) - 4.820;
}

Eigen::Vector2d PassiveElasticTorque(PassiveModel model, const Eigen::Vector2d& q) {
  if (model == PassiveModel::kNone) return Eigen::Vector2d::Zero();
  const double H = q[0] * kDegPerRad;
  const double K = -q[1] * kDegPerRad;
  return Eigen::Vector2d(-RienerHipMoment(H, K), RienerKneeMoment(0.0, K, H));
}

}  // namespace exotwin
