#include "model/regressors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "model/leg_dynamics.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

LumpedParams RandomParams(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LumpedParams p;
  p.J2 = 0.3 + 0.8 * u(rng);
  p.J1 = 1.5 + 4.0 * u(rng);
  p.X1 = 3.0 + 6.0 * u(rng);
  p.X2 = 0.8 + 2.5 * u(rng);
  p.Y1 = -0.6 + 1.2 * u(rng);
  p.Y2 = -0.6 + 1.2 * u(rng);
  return p;
}

// Regressor times parameters equals the closed-form inverse dynamics for random states/parameters.
TEST(Regressors, FullRegressorTimesParametersEqualsInverseDynamics) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> s(-3.0, 3.0);
  for (int k = 0; k < 200; ++k) {
    const LumpedParams p = RandomParams(rng);
    const double L1 = 0.35 + 0.1 * std::abs(s(rng)) / 3.0;
    const Eigen::Vector2d q(s(rng), s(rng)), qd(s(rng), s(rng)), qdd(5 * s(rng), 5 * s(rng));
    const Eigen::Vector2d ref = RigidInverseDynamics(p, L1, 9.81, q, qd, qdd);
    const Eigen::Vector2d reg = FullRegressor(L1, 9.81, q, qd, qdd) * ToVector(p);
    EXPECT_NEAR(reg[0], ref[0], 1e-10 * (1 + ref.norm()));
    EXPECT_NEAR(reg[1], ref[1], 1e-10 * (1 + ref.norm()));
  }
}

// Steps 1-4 of the protocol (HJ15 eq. 14-17 with the signs re-derived): u* = w' phi where u is the
// torque the closed form gives with the other joint held (hip at 90 deg, or knee at -90 deg).
TEST(Regressors, StepRowsMatchClosedForm) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> s(-1.0, 1.0);
  const double g = 9.81;
  for (int k = 0; k < 100; ++k) {
    LegParams lp;
    lp.L1 = 0.4;
    lp.exo = RandomParams(rng);
    lp.human = RandomParams(rng);
    lp.passive = PassiveModel::kRiener1999;
    const LumpedParams& R = lp.exo;
    const LumpedParams& H = *lp.human;
    const double y = 0.7 * s(rng), yd = 2 * s(rng), ydd = 10 * s(rng);

    // Knee swinging, hip held at 90 deg (steps 1 and 3).
    const Eigen::Vector2d qk(M_PI / 2, y - 0.6), qdk(0, yd), qddk(0, ydd);
    {
      LegParams exo_only = lp;
      exo_only.human.reset();
      const double u1 = ActuatorTorque(exo_only, qk, qdk, qddk)[1];
      const StepRow r1 = Step1Row(g, qk[1], ydd, u1);
      EXPECT_NEAR(r1.u_star, r1.w.dot(Eigen::Vector3d(R.J2, R.X2, R.Y2)), 1e-9);
      const double u3 = ActuatorTorque(lp, qk, qdk, qddk)[1];
      const double P2 = PassiveElasticTorque(lp.passive, qk)[1];
      const StepRow r3 = Step3Row(g, R, qk[1], ydd, u3, P2);
      EXPECT_NEAR(r3.u_star, r3.w.dot(Eigen::Vector3d(H.J2, H.X2, H.Y2)), 1e-9);
    }
    // Hip swinging, knee held at -90 deg (steps 2 and 4).
    const Eigen::Vector2d qh(y + 0.4, -M_PI / 2), qdh(yd, 0), qddh(ydd, 0);
    {
      LegParams exo_only = lp;
      exo_only.human.reset();
      const double u2 = ActuatorTorque(exo_only, qh, qdh, qddh)[0];
      const StepRow r2 = Step2Row(lp.L1, g, R, qh[0], ydd, u2);
      EXPECT_NEAR(r2.u_star, r2.w.dot(Eigen::Vector3d(R.J1, R.X1, R.Y1)), 1e-9);
      const double u4 = ActuatorTorque(lp, qh, qdh, qddh)[0];
      const double P1 = PassiveElasticTorque(lp.passive, qh)[0];
      const StepRow r4 = Step4Row(lp.L1, g, R, H, qh[0], ydd, u4, P1);
      EXPECT_NEAR(r4.u_star, r4.w.dot(Eigen::Vector3d(H.J1, H.X1, H.Y1)), 1e-9);
    }
  }
}

// The printed HJ15 eq. 15 "J1 - 2 L1 Y2" would fail: with Y2 != 0 and y'' != 0 it misses 4 L1 Y2 y''.
TEST(Regressors, PrintedSignOfEq15IsWrong) {
  LegParams lp;
  lp.L1 = 0.41;
  lp.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  const double y = 0.3, ydd = 5.0;
  const double u = ActuatorTorque(lp, {y, -M_PI / 2}, {0, 0}, {ydd, 0})[0];
  const double printed = (lp.exo.J1 - 2 * lp.L1 * lp.exo.Y2) * ydd +
                         9.81 * (lp.exo.X1 * std::sin(y) + lp.exo.Y1 * std::cos(y) -
                                 lp.exo.X2 * std::cos(y) + lp.exo.Y2 * std::sin(y));
  EXPECT_NEAR(u - printed, 4 * lp.L1 * lp.exo.Y2 * ydd, 1e-9);
}


// The regressor from precomputed trigonometry is FullRegressor's, bit for bit.
TEST(Regressors, FullRegressorOfTrigEqualsFullRegressor) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d q(u(rng), u(rng)), qd(u(rng), u(rng)), qdd(u(rng), u(rng));
    const Matrix26 a = FullRegressor(0.41, 9.81, q, qd, qdd);
    const Matrix26 b = FullRegressorOfTrig(0.41, 9.81, TrigOf(q), qd, qdd);
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 6; ++c) EXPECT_EQ(a(r, c), b(r, c));
  }
}

}  // namespace
}  // namespace exotwin
