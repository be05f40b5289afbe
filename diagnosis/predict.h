// `exotwin predict`: the torque-sensor reading the twin expects for measured kinematics.
#pragma once
#include <vector>

#include "formats/measured_data.h"
#include "sim/plant.h"

namespace exotwin {

struct Prediction {
  std::vector<double> t;
  std::vector<double> tau_R[2];  // actuator torque, N m (hip, knee)
  std::vector<double> tau_S[2];  // predicted sensor reading tau_S = -tau_R (HJ15 eq. 8) + sensor effects
};

// Runs MuJoCo's inverse dynamics of `plant` (whose parameters are set) on every sample, adds the
// passive torque and the effects of plant.params(). Throws SimulationError on non-finite output.
Prediction PredictTorque(Plant& plant, const Kinematics& kin);
// The same with the samples split into contiguous ranges, one per plant, on as many threads: each of
// `plants` a twin of plants[0] (the same MJCF, parameters and effects; MuJoCo's inverse dynamics
// writes its plant's model and data). The same bits as PredictTorque(*plants[0], kin).
Prediction PredictTorque(const std::vector<Plant*>& plants, const Kinematics& kin);

// Root-mean-square of a - b.
double Rmse(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace exotwin
