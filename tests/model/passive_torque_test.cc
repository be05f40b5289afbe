#include "model/passive_torque.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/units.h"

namespace exotwin {
namespace {


// Magnitudes of the original law (papers/README.md, checked against two public implementations):
// hip 0, ankle 0: M_K = +10.4, -2.7, -4.5, -6.2 N m at knee flexion 0, 30, 60, 90 deg.
TEST(PassiveTorque, RienerKneeMagnitudes) {
  EXPECT_NEAR(RienerKneeMoment(0, 0, 0), 10.4, 0.05);
  EXPECT_NEAR(RienerKneeMoment(0, 30, 0), -2.7, 0.05);
  EXPECT_NEAR(RienerKneeMoment(0, 60, 0), -4.5, 0.05);
  EXPECT_NEAR(RienerKneeMoment(0, 90, 0), -6.2, 0.05);
}

// knee 0: M_H = +14.4, +8.6, -1.0, -15.7 N m at hip -10, 0, 30, 60 deg.
TEST(PassiveTorque, RienerHipMagnitudes) {
  EXPECT_NEAR(RienerHipMoment(-10, 0), 14.4, 0.05);
  EXPECT_NEAR(RienerHipMoment(0, 0), 8.6, 0.05);
  EXPECT_NEAR(RienerHipMoment(30, 0), -1.0, 0.05);
  EXPECT_NEAR(RienerHipMoment(60, 0), -15.7, 0.05);
}

// The laws as printed by Riener & Edrich 1999 (the comment of passive_torque.cc), written out here:
// the term tables the library evaluates give them bit for bit.
TEST(PassiveTorque, TermTablesGiveThePrintedLawsBitForBit) {
  for (double H = -30; H <= 90; H += 7.3)
    for (double K = -5; K <= 120; K += 6.1)
      for (double A : {0.0, -12.5, 20.0}) {
        EXPECT_EQ(RienerHipMoment(H, K),
                  std::exp(1.4655 - 0.0034 * K - 0.0750 * H) - std::exp(1.3403 - 0.0226 * K + 0.0305 * H) + 8.072);
        EXPECT_EQ(RienerKneeMoment(A, K, H), std::exp(1.800 - 0.0460 * A - 0.0352 * K + 0.0217 * H) -
                                                 std::exp(-3.971 - 0.0004 * A + 0.0495 * K - 0.0128 * H) +
                                                 std::exp(2.220 - 0.150 * K) - 4.820);
      }
}

// PassiveNearPoints: P at q bit for bit, at q +- h e_j within a few ulps of the terms (1e-13 N m on
// moments of ~10 N m), and their central difference within 1e-6 of the one of PassiveElasticTorque
// (h = 1e-5 rad: the difference's rounding, ~1e-15 / 1e-5, bounds both).
TEST(PassiveTorque, NearPointsEqualTheDirectEvaluation) {
  constexpr double h = 1e-5;
  for (int j = 0; j < 2; ++j) {
    const PassiveNearPoints near(PassiveModel::kRiener1999, j, h);
    for (double th1 = -0.4; th1 <= 1.2; th1 += 0.13)
      for (double th2 = -1.6; th2 <= 0.1; th2 += 0.11) {
        const Eigen::Vector2d q(th1, th2);
        Eigen::Vector2d out[3];
        near.At(q, out);
        EXPECT_EQ(out[0], PassiveElasticTorque(PassiveModel::kRiener1999, q));
        Eigen::Vector2d up = q, down = q;
        up[j] += h, down[j] -= h;
        const Eigen::Vector2d P_up = PassiveElasticTorque(PassiveModel::kRiener1999, up);
        const Eigen::Vector2d P_down = PassiveElasticTorque(PassiveModel::kRiener1999, down);
        EXPECT_LT((out[1] - P_up).cwiseAbs().maxCoeff(), 1e-13);
        EXPECT_LT((out[2] - P_down).cwiseAbs().maxCoeff(), 1e-13);
        EXPECT_LT(((out[1] - out[2]) - (P_up - P_down)).cwiseAbs().maxCoeff() / (2 * h), 1e-6);
      }
    Eigen::Vector2d none[3];
    PassiveNearPoints(PassiveModel::kNone, j, h).At({0.3, -0.5}, none);
    for (const Eigen::Vector2d& v : none) EXPECT_EQ(v, Eigen::Vector2d::Zero());
  }
}

// Convention mapping: H = deg(th1), K = -deg(th2), P1 = -M_H, P2 = +M_K.
TEST(PassiveTorque, ConventionMapping) {
  const Eigen::Vector2d q(20 * kRadPerDeg, -45 * kRadPerDeg);
  const Eigen::Vector2d P = PassiveElasticTorque(PassiveModel::kRiener1999, q);
  EXPECT_NEAR(P[0], -RienerHipMoment(20, 45), 1e-12);
  EXPECT_NEAR(P[1], RienerKneeMoment(0, 45, 20), 1e-12);
  // Physical sign check: a straight knee (th2 = 0) is pushed towards flexion by the passive structures
  // (M_K > 0 = flexion moment): the generalized force -P2 along th2 must be negative (flexion).
  const Eigen::Vector2d P0 = PassiveElasticTorque(PassiveModel::kRiener1999, Eigen::Vector2d(0, 0));
  EXPECT_LT(-P0[1], 0.0);
  EXPECT_EQ(PassiveElasticTorque(PassiveModel::kNone, q), Eigen::Vector2d::Zero());
}

// Over the gait range (hip -10..25 deg, knee 0..-65 deg) the passive torque stays within a few N m
// except near full knee extension, where Riener's knee law rises to about 10 N m.
TEST(PassiveTorque, BoundedOverGaitRange) {
  double max_hip = 0, max_knee = 0;
  for (double h = -10; h <= 25; h += 1)
    for (double k = 5; k <= 65; k += 1) {
      const Eigen::Vector2d P = PassiveElasticTorque(PassiveModel::kRiener1999, {h * kRadPerDeg, -k * kRadPerDeg});
      max_hip = std::max(max_hip, std::abs(P[0]));
      max_knee = std::max(max_knee, std::abs(P[1]));
    }
  EXPECT_LT(max_hip, 15.0);
  EXPECT_LT(max_knee, 9.0);  // 8.2 N m at 5 deg flexion, the end of the gait range
  double max_knee_mid = 0;
  for (double k = 15; k <= 65; k += 1)
    max_knee_mid = std::max(max_knee_mid, std::abs(PassiveElasticTorque(
                                              PassiveModel::kRiener1999, {10 * kRadPerDeg, -k * kRadPerDeg})[1]));
  EXPECT_LT(max_knee_mid, 5.0);
  EXPECT_GT(max_hip, 1.0);  // not identically zero
}

}  // namespace
}  // namespace exotwin
