#include "model/leg_dynamics.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "model/passive_torque.h"

namespace exotwin {
namespace {

// Subject S1 of Hwang & Jeon: exo from Table 3, human from Table 4, L1 = 0.41 m.
LegParams S1() {
  LegParams p;
  p.L1 = 0.41;
  p.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  p.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
  p.passive = PassiveModel::kRiener1999;
  return p;
}

// data/reference_dynamics.csv was computed by an independent closed form whose energy balance was
// checked; it pins HJ15 eq. 5-7 and the Riener mapping to numbers this code did not produce.
TEST(LegDynamics, MatchesReferenceTable) {
  std::ifstream in(std::string(EXOTWIN_SOURCE_DIR) + "/data/reference_dynamics.csv");
  ASSERT_TRUE(in);
  std::string line;
  int rows = 0;
  const LegParams p = S1();
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'q') continue;
    std::stringstream ss(line);
    std::vector<double> v;
    std::string f;
    while (std::getline(ss, f, ',')) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 10u);
    const Vec2 q(v[0], v[1]), qd(v[2], v[3]), qdd(v[4], v[5]);
    const Vec2 tau = RigidInverseDynamics(p.Total(), p.L1, p.g, q, qd, qdd);
    EXPECT_NEAR(tau[0], v[6], 1e-8 * (1 + std::abs(v[6])));
    EXPECT_NEAR(tau[1], v[7], 1e-8 * (1 + std::abs(v[7])));
    const Vec2 P = PassiveElasticTorque(PassiveModel::kRiener1999, q);
    EXPECT_NEAR(P[0], v[8], 1e-8);
    EXPECT_NEAR(P[1], v[9], 1e-8);
    ++rows;
  }
  EXPECT_EQ(rows, 16);
}

// Power balance: with tau = M qdd + V + G, d(T + V_grav)/dt = tau . qd. Checked by integrating a
// trajectory with a fine RK4 step and comparing the energy change with the work done.
TEST(LegDynamics, EnergyBalance) {
  const LegParams p = S1();
  const LumpedParams tot = p.Total();
  auto acc = [&](const Vec2& q, const Vec2& qd, const Vec2& tau) {
    const Vec2 rhs = tau - CoriolisCentrifugal(tot, p.L1, q, qd) - GravityTorque(tot, p.g, q);
    return Vec2(MassMatrix(tot, p.L1, q[1]).ldlt().solve(rhs));
  };
  auto torque = [](double t) { return Vec2(20 * std::sin(3 * t), -8 * std::cos(5 * t)); };
  Vec2 q(0.3, -0.8), qd(1.0, -2.0);
  const double h = 1e-4;
  double work = 0;
  const double E0 = MechanicalEnergy(tot, p.L1, p.g, q, qd);
  for (int i = 0; i < 20000; ++i) {
    const double t = i * h;
    // RK4 on (q, qd, work).
    auto f = [&](double tt, const Vec2& qq, const Vec2& vv, Vec2* dq, Vec2* dv, double* dw) {
      *dq = vv;
      *dv = acc(qq, vv, torque(tt));
      *dw = torque(tt).dot(vv);
    };
    Vec2 k1q, k1v, k2q, k2v, k3q, k3v, k4q, k4v;
    double k1w, k2w, k3w, k4w;
    f(t, q, qd, &k1q, &k1v, &k1w);
    f(t + h / 2, q + h / 2 * k1q, qd + h / 2 * k1v, &k2q, &k2v, &k2w);
    f(t + h / 2, q + h / 2 * k2q, qd + h / 2 * k2v, &k3q, &k3v, &k3w);
    f(t + h, q + h * k3q, qd + h * k3v, &k4q, &k4v, &k4w);
    q += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
    qd += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    work += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
  const double E1 = MechanicalEnergy(tot, p.L1, p.g, q, qd);
  EXPECT_NEAR(E1 - E0, work, 1e-7 * (1 + std::abs(work)));
}

// M(q) is symmetric positive definite for realistic parameters over the joint range.
TEST(LegDynamics, MassMatrixPositiveDefinite) {
  const LegParams p = S1();
  for (double th2 = -2.4; th2 <= 0.2; th2 += 0.05) {
    const Eigen::Matrix2d M = MassMatrix(p.Total(), p.L1, th2);
    EXPECT_DOUBLE_EQ(M(0, 1), M(1, 0));
    EXPECT_GT(M.determinant(), 0.0);
    EXPECT_GT(M(0, 0), 0.0);
  }
}

// M(q) against the Hessian of the kinetic energy by finite differences of the power: T = 1/2 qd'M qd
// must satisfy dT/dqd = M qd, checked with central differences of T.
TEST(LegDynamics, CoriolisFromChristoffelByFiniteDifferences) {
  const LegParams p = S1();
  const LumpedParams tot = p.Total();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int k = 0; k < 20; ++k) {
    const Vec2 q(u(rng), u(rng) - 0.8), qd(u(rng) * 2, u(rng) * 2);
    // V_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k; dM/dq1 = 0, dM/dq2 by central difference.
    const double e = 1e-6;
    const Eigen::Matrix2d dM2 =
        (MassMatrix(tot, p.L1, q[1] + e) - MassMatrix(tot, p.L1, q[1] - e)) / (2 * e);
    Vec2 V_fd;
    V_fd[0] = dM2.row(0).dot(qd) * qd[1];
    V_fd[1] = dM2.row(1).dot(qd) * qd[1] - 0.5 * qd.dot(dM2 * qd);
    const Vec2 V = CoriolisCentrifugal(tot, p.L1, q, qd);
    EXPECT_NEAR(V[0], V_fd[0], 1e-6);
    EXPECT_NEAR(V[1], V_fd[1], 1e-6);
    // Gravity as the gradient of the potential energy (MechanicalEnergy at qd = 0).
    const Vec2 G = GravityTorque(tot, p.g, q);
    for (int i = 0; i < 2; ++i) {
      Vec2 dq = Vec2::Zero();
      dq[i] = e;
      const double dV = (MechanicalEnergy(tot, p.L1, p.g, q + dq, Vec2::Zero()) -
                         MechanicalEnergy(tot, p.L1, p.g, q - dq, Vec2::Zero())) /
                        (2 * e);
      EXPECT_NEAR(G[i], dV, 1e-6);
    }
  }
}

}  // namespace
}  // namespace exotwin
