// Tests of controller/muscular_torque.h: HJ15 eq. 8-10 round trip with a known muscular torque on a
// smooth gait-like motion, relaxed -> ~0 with off-line derivatives, and the effect of a parameter error.
#include "controller/muscular_torque.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "dsp/derivatives.h"
#include "model/leg_dynamics.h"

namespace exotwin::controller {
namespace {

LegParams Params() {  // DESIGN.md example model with Riener passive torque
  LegParams p;
  p.L1 = 0.41;
  p.exo = {3.01, 0.74, 3.85, 1.73, 0.14, 0.18};
  p.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
  p.passive = PassiveModel::kRiener1999;
  return p;
}

struct Motion {
  std::vector<Eigen::Vector2d> q, qd, qdd, tau_M, tau_S;
};

// Gait-like motion at 0.8 Hz; tau_S by HJ15 eq. 8: tau_S = tau_M - (M qdd + V + G + P).
Motion Make(const LegParams& truth, bool active, double dt = 1e-3, int n = 6000) {
  Motion m;
  const double w = 2 * M_PI * 0.8;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const Eigen::Vector2d q(0.3 + 0.35 * std::sin(w * t), -0.6 + 0.5 * std::sin(w * t - 1.2));
    const Eigen::Vector2d qd(0.35 * w * std::cos(w * t), 0.5 * w * std::cos(w * t - 1.2));
    const Eigen::Vector2d qdd(-0.35 * w * w * std::sin(w * t), -0.5 * w * w * std::sin(w * t - 1.2));
    const Eigen::Vector2d tm = active ? Eigen::Vector2d(15 * std::sin(3.1 * t), -10 * std::cos(2.3 * t))
                                      : Eigen::Vector2d(0, 0);
    m.q.push_back(q);
    m.qd.push_back(qd);
    m.qdd.push_back(qdd);
    m.tau_M.push_back(tm);
    m.tau_S.push_back(tm - ActuatorTorque(truth, q, qd, qdd));
  }
  return m;
}

TEST(MuscularTorque, ExactKinematicsRecoverTheMuscularTorque) {
  const LegParams p = Params();
  const Motion m = Make(p, true);
  for (size_t k = 0; k < m.q.size(); k += 97) {
    const Eigen::Vector2d tm = MuscularTorque(p, m.q[k], m.qd[k], m.qdd[k], m.tau_S[k]);
    EXPECT_NEAR((tm - m.tau_M[k]).norm(), 0.0, 1e-9);
  }
  // tau_PAS is the sensor reading of the relaxed system.
  EXPECT_NEAR((PassiveTorqueEstimate(p, m.q[5], m.qd[5], m.qdd[5]) - Make(p, false).tau_S[5]).norm(),
              0.0, 1e-12);
}

// HJ15 eq. 9 on kinematics derived as off line (dsp::ZeroPhaseDerivatives, 20 Hz): relaxed -> ~0.
TEST(MuscularTorque, OfflineDerivativesRelaxedGivesNearZero) {
  const LegParams p = Params();
  const Motion m = Make(p, false);
  const double dt = 1e-3;
  dsp::Derivatives d[2];
  for (int j = 0; j < 2; ++j) {
    std::vector<double> x(m.q.size());
    for (size_t k = 0; k < m.q.size(); ++k) x[k] = m.q[k][j];
    d[j] = dsp::ZeroPhaseDerivatives(x, dt, 20.0);
  }
  double worst = 0;
  for (size_t k = 200; k + 200 < m.q.size(); ++k) {
    const Eigen::Vector2d tm = MuscularTorque(p, m.q[k], {d[0].first[k], d[1].first[k]},
                                              {d[0].second[k], d[1].second[k]}, m.tau_S[k]);
    worst = std::max(worst, tm.cwiseAbs().maxCoeff());
  }
  std::printf("[tau_M] relaxed, exact parameters, 20 Hz zero-phase derivatives: max |tau_M| %.3f N m\n",
              worst);
  EXPECT_LT(worst, 0.1);
}

TEST(MuscularTorque, ParameterErrorShowsAsSpuriousMuscularTorque) {
  const LegParams truth = Params();
  LegParams wrong = truth;
  wrong.human->X2 *= 1.1;  // 10 % error of the lower-leg first moment
  const Motion m = Make(truth, false);
  double worst = 0;
  for (size_t k = 0; k < m.q.size(); k += 10)
    worst = std::max(worst, std::abs(MuscularTorque(wrong, m.q[k], m.qd[k], m.qdd[k], m.tau_S[k])[1]));
  EXPECT_GT(worst, 0.5);  // ~0.1 * g * 1.2 kg m * |sin| at the knee
}

}  // namespace
}  // namespace exotwin::controller
