// Tests of controller/pd_controller.h: the control law, saturation, non-finite inputs, and closed
// loops on a double integrator J qdd = tau coded here (step response, and tracking an exciting
// trajectory with quantized encoder + the causal state estimator).
#include "controller/pd_controller.h"

#include <gtest/gtest.h>

#include <cmath>

#include "controller/state_estimator.h"
#include "core/error.h"
#include "core/units.h"

namespace exotwin::controller {
namespace {


TEST(JointPdController, ControlLawAndSaturation) {
  const JointPdController pd({100.0, 5.0, 20.0});
  double tau = -1;
  EXPECT_EQ(pd.Update({0.1, 0.2, 0.0}, 0.05, 0.1, 1.5, &tau), PdStatus::kOk);
  EXPECT_DOUBLE_EQ(tau, 1.5 + 100.0 * 0.05 + 5.0 * 0.1);
  EXPECT_EQ(pd.Update({1.0, 0.0, 0.0}, 0.0, 0.0, 0.0, &tau), PdStatus::kSaturated);
  EXPECT_EQ(tau, 20.0);
  EXPECT_EQ(pd.Update({-1.0, 0.0, 0.0}, 0.0, 0.0, 0.0, &tau), PdStatus::kSaturated);
  EXPECT_EQ(tau, -20.0);
}

TEST(JointPdController, NonFiniteInputGivesZeroTorque) {
  const JointPdController pd({100.0, 5.0, 20.0});
  const double bad[] = {NAN, INFINITY, -INFINITY};
  for (double b : bad) {
    double tau = 7;
    EXPECT_EQ(pd.Update({b, 0, 0}, 0, 0, 0, &tau), PdStatus::kNonFinite);
    EXPECT_EQ(tau, 0.0);
    EXPECT_EQ(pd.Update({0, 0, 0}, b, 0, 0, &tau), PdStatus::kNonFinite);
    EXPECT_EQ(pd.Update({0, 0, 0}, 0, b, 0, &tau), PdStatus::kNonFinite);
    EXPECT_EQ(pd.Update({0, b, 0}, 0, 0, 0, &tau), PdStatus::kNonFinite);
    EXPECT_EQ(pd.Update({0, 0, 0}, 0, 0, b, &tau), PdStatus::kNonFinite);
    EXPECT_EQ(tau, 0.0);
  }
}

TEST(JointPdController, RejectsBadGains) {
  EXPECT_THROW(JointPdController({-1, 0, 1}), InputError);
  EXPECT_THROW(JointPdController({1, -1, 1}), InputError);
  EXPECT_THROW(JointPdController({1, 1, 0}), InputError);
  EXPECT_THROW(JointPdController({NAN, 1, 1}), InputError);
}

TEST(LegPdController, WorstStatusOfBothJoints) {
  const LegPdController pd({50, 2, 10}, {50, 2, 10});
  double th, tk;
  EXPECT_EQ(pd.Update({0, 0, 0}, {0, 0, 0}, 0, 0, 0, 0, 0, 0, &th, &tk), PdStatus::kOk);
  EXPECT_EQ(pd.Update({1, 0, 0}, {0, 0, 0}, 0, 0, NAN, 0, 0, 0, &th, &tk), PdStatus::kNonFinite);
  EXPECT_EQ(th, 10.0);
  EXPECT_EQ(tk, 0.0);
}

// Double integrator J qdd = tau, semi-implicit Euler at 1 kHz.
struct Plant {
  double J, q = 0, qd = 0;
  void Step(double tau, double dt) {
    qd += tau / J * dt;
    q += qd * dt;
  }
};

TEST(JointPdController, StepResponseConvergesOnDoubleIntegrator) {
  const double J = 0.5, kp = 100.0, kd = 2.0 * std::sqrt(kp * J);  // critically damped
  const JointPdController pd({kp, kd, 50.0});
  Plant p{J};
  const double dt = 1e-3;
  const JointSetpoint ref{0.3, 0.0, 0.0};
  double overshoot = 0;
  for (int i = 0; i < 3000; ++i) {
    double tau;
    ASSERT_NE(pd.Update(ref, p.q, p.qd, 0.0, &tau), PdStatus::kNonFinite);
    p.Step(tau, dt);
    overshoot = std::max(overshoot, p.q - ref.q);
  }
  EXPECT_NEAR(p.q, 0.3, 1e-5);
  EXPECT_NEAR(p.qd, 0.0, 1e-4);
  EXPECT_LT(overshoot, 0.01 * 0.3);  // critically damped: (almost) no overshoot
}

TEST(JointPdController, TracksExcitingTrajectoryWithEstimatedVelocity) {
  // Knee-like joint: quantized 14-bit encoder, causal estimator, feed-forward J qdd_ref.
  const double J = 0.4, kp = 200.0, kd = 10.0, dt = 1e-3, lsb = 2 * M_PI / 16384;
  const JointPdController pd({kp, kd, 40.0});
  const HarmonicTrajectory tr = HarmonicTrajectory::Design(ExcitationSpec::PaperKnee(), 11);
  JointStateEstimator est;
  Plant p{J, tr.StartPose(), 0.0};
  double sq = 0, max_err = 0;
  const int n = static_cast<int>(tr.Period() / dt);
  for (int i = 0; i < n; ++i) {
    const JointSetpoint ref = tr.At(i * dt);
    est.Update(std::round(p.q / lsb) * lsb);
    double tau;
    pd.Update(ref, est.estimate().q, est.estimate().qd, J * ref.qdd, &tau);
    const double e = ref.q - p.q;
    sq += e * e;
    max_err = std::max(max_err, std::abs(e));
    p.Step(tau, dt);
  }
  const double rms = std::sqrt(sq / n);
  std::printf("tracking rms %.3f deg, max %.3f deg\n", rms / kRadPerDeg, max_err / kRadPerDeg);
  EXPECT_LT(rms, 0.5 * kRadPerDeg);
  EXPECT_LT(max_err, 1.5 * kRadPerDeg);
}

}  // namespace
}  // namespace exotwin::controller
