// Tests of controller/state_estimator.h on known signals. Stated bounds (defaults: fs 1 kHz,
// 20 Hz / 20 Hz, order 2; 14-bit encoder, 0.5 rad sine at 1 Hz):
//   velocity lag 11.0..12.5 ms (11.75 ms computed), |gain - 1| < 0.2 %; after removing the predicted lag and gain the
//   residual is < 0.01 rad/s (0.3 % of the 3.14 rad/s amplitude); without compensation the error
//   is < 0.08 * amplitude (the lag itself, 2 pi f tau = 7.4 %).
//   acceleration lag < 25 ms (23.5 ms); residual after lag compensation < 0.75 rad/s^2 (3.8 % of
//   the 19.7 rad/s^2 amplitude; dominated by quantization noise, 0.50 measured).
#include "controller/state_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace exotwin::controller {
namespace {

constexpr double kLsb = 2 * M_PI / 16384;  // 14-bit encoder
double Quantize(double q) { return std::round(q / kLsb) * kLsb; }

TEST(JointStateEstimator, DocumentedLagAtOneHertz) {
  JointStateEstimator est;
  const double tv = est.VelocityDelay(1.0), ta = est.AccelerationDelay(1.0);
  const double gv = std::abs(est.VelocityResponse(1.0)), ga = std::abs(est.AccelerationResponse(1.0));
  std::printf("1 Hz: velocity lag %.2f ms gain %.5f, acceleration lag %.2f ms gain %.5f\n",
              tv * 1e3, gv, ta * 1e3, ga);
  EXPECT_GT(tv, 11.0e-3);
  EXPECT_LT(tv, 12.5e-3);
  EXPECT_NEAR(gv, 1.0, 2e-3);
  EXPECT_LT(ta, 25e-3);
  EXPECT_NEAR(ga, 1.0, 5e-3);
}

TEST(JointStateEstimator, QuantizedSineAtOneHertz) {
  JointStateEstimator est;
  const double A = 0.5, f = 1.0, w = 2 * M_PI * f, dt = 1e-3, q0 = -0.6;
  const double tv = est.VelocityDelay(f), ta = est.AccelerationDelay(f);
  const double gv = std::abs(est.VelocityResponse(f)), ga = std::abs(est.AccelerationResponse(f));
  double e_model_v = 0, e_true_v = 0, e_model_a = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * dt;
    ASSERT_EQ(est.Update(Quantize(q0 + A * std::sin(w * t))), EstimatorStatus::kOk);
    if (t < 1.0) continue;  // start-up transient (the filters start at rest)
    const JointSetpoint& s = est.estimate();
    EXPECT_NEAR(s.q, q0 + A * std::sin(w * t), kLsb);
    e_model_v = std::max(e_model_v, std::abs(s.qd - gv * A * w * std::cos(w * (t - tv))));
    e_true_v = std::max(e_true_v, std::abs(s.qd - A * w * std::cos(w * t)));
    e_model_a = std::max(e_model_a, std::abs(s.qdd + ga * A * w * w * std::sin(w * (t - ta))));
  }
  std::printf("velocity residual %.4f rad/s (lag-compensated), %.4f rad/s (raw); accel %.3f rad/s^2\n",
              e_model_v, e_true_v, e_model_a);
  EXPECT_LT(e_model_v, 0.01);
  EXPECT_LT(e_true_v, 0.08 * A * w);
  EXPECT_LT(e_model_a, 0.75);
}

TEST(JointStateEstimator, ResponseFunctionMatchesSimulationAtFiveHertz) {
  // Without quantization the steady-state output is exactly |H| A w cos(w (t - tau)).
  JointStateEstimator est;
  const double A = 0.1, f = 5.0, w = 2 * M_PI * f, dt = 1e-3;
  const double tv = est.VelocityDelay(f), gv = std::abs(est.VelocityResponse(f));
  double err = 0;
  for (int i = 0; i < 3000; ++i) {
    const double t = i * dt;
    est.Update(A * std::sin(w * t));
    if (t > 1.5) err = std::max(err, std::abs(est.estimate().qd - gv * A * w * std::cos(w * (t - tv))));
  }
  EXPECT_LT(err, 1e-6 * A * w);
}

TEST(JointStateEstimator, RampGivesExactVelocityAndZeroAcceleration) {
  JointStateEstimator est;
  for (int i = 0; i < 2000; ++i) est.Update(0.2 + 0.7 * i * 1e-3);
  EXPECT_NEAR(est.estimate().qd, 0.7, 1e-9);
  EXPECT_NEAR(est.estimate().qdd, 0.0, 1e-6);
}

TEST(JointStateEstimator, FirstSampleAtRestNonFiniteIgnoredAndHold) {
  JointStateEstimator est;
  EXPECT_FALSE(est.initialised());
  est.Update(0.4);
  EXPECT_EQ(est.estimate().q, 0.4);
  EXPECT_EQ(est.estimate().qd, 0.0);
  for (int i = 1; i < 2000; ++i) est.Update(0.4 + 0.5 * i * 1e-3);
  const JointSetpoint before = est.estimate();
  EXPECT_EQ(est.Update(NAN), EstimatorStatus::kNonFinite);
  EXPECT_EQ(est.Update(INFINITY), EstimatorStatus::kNonFinite);
  // Treated as held (extrapolated) samples: estimate stays finite and the velocity is kept.
  EXPECT_TRUE(std::isfinite(est.estimate().q));
  EXPECT_NEAR(est.estimate().qd, before.qd, 1e-9);
  EXPECT_NEAR(est.estimate().q, before.q + 2 * before.qd * 1e-3, 1e-12);
  est.Reset();
  EXPECT_FALSE(est.initialised());
}

TEST(JointStateEstimator, RejectsBadConfig) {
  EstimatorConfig c;
  c.velocity_cutoff_hz = 600;  // above fs/2
  EXPECT_THROW(JointStateEstimator{c}, InputError);
  c = EstimatorConfig();
  c.sample_rate_hz = 0;
  EXPECT_THROW(JointStateEstimator{c}, InputError);
  c = EstimatorConfig();
  c.order = 0;
  EXPECT_THROW(JointStateEstimator{c}, InputError);
}

}  // namespace
}  // namespace exotwin::controller
