#include "diagnosis/predict.h"

#include <cmath>

#include "diagnosis/effects.h"

namespace exotwin {

Prediction PredictTorque(Plant& plant, const Kinematics& kin) {
  Prediction p;
  p.t = kin.t;
  const size_t n = kin.t.size();
  for (auto& v : p.tau_R) v.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d tau =
        plant.InverseDynamics({kin.q[0][i], kin.q[1][i]}, {kin.qd[0][i], kin.qd[1][i]},
                              {kin.qdd[0][i], kin.qdd[1][i]});
    if (!std::isfinite(tau[0]) || !std::isfinite(tau[1]))
      throw SimulationError(kin.t[i], "inverse dynamics returned a non-finite torque");
    p.tau_R[0][i] = tau[0];
    p.tau_R[1][i] = tau[1];
  }
  ApplyEffects(plant.params(), kin, p.tau_R, p.tau_S);
  return p;
}

double Rmse(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  const size_t n = std::min(a.size(), b.size());
  for (size_t i = 0; i < n; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return n ? std::sqrt(s / static_cast<double>(n)) : 0.0;
}

}  // namespace exotwin
