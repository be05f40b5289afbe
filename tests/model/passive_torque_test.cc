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
