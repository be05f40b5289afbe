#include "diagnosis/predict.h"

#include <cmath>

#include "core/parallel_for.h"
#include "diagnosis/effects.h"

namespace exotwin {

Prediction PredictTorque(Plant& plant, const Kinematics& kin) { return PredictTorque(std::vector<Plant*>{&plant}, kin); }

Prediction PredictTorque(const std::vector<Plant*>& plants, const Kinematics& kin) {
  Prediction p;
  p.t = kin.t;
  const size_t n = kin.t.size(), T = plants.size();
  for (auto& v : p.tau_R) v.resize(n);
  // Each range on its own plant; a non-finite torque is reported at the first such sample.
  ParallelFor(T, static_cast<int>(T), [&](size_t k) {
    Plant& plant = *plants[k];
    for (size_t i = k * n / T; i < (k + 1) * n / T; ++i) {
      const Eigen::Vector2d tau =
          plant.InverseDynamics({kin.q[0][i], kin.q[1][i]}, {kin.qd[0][i], kin.qd[1][i]},
                                {kin.qdd[0][i], kin.qdd[1][i]});
      p.tau_R[0][i] = tau[0];
      p.tau_R[1][i] = tau[1];
    }
  });
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(p.tau_R[0][i]) || !std::isfinite(p.tau_R[1][i]))
      throw SimulationError(kin.t[i], "inverse dynamics returned a non-finite torque");
  ApplyEffects(plants[0]->params(), kin, p.tau_R, p.tau_S);
  return p;
}

double Rmse(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  const size_t n = std::min(a.size(), b.size());
  for (size_t i = 0; i < n; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return n ? std::sqrt(s / static_cast<double>(n)) : 0.0;
}

}  // namespace exotwin
