// MuJoCo's inverse dynamics of models/leg_exowheel.xml, with lumped parameters written in at run time,
// against the closed form of HJ15 eq. 5-7 + P: the proof that the twin's physics is the paper's model.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <mujoco/mujoco.h>

#include <cmath>
#include <random>

#include "core/error.h"
#include "model/leg_dynamics.h"
#include "model/regressors.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

LumpedParams RandomValid(std::mt19937_64& rng, double L1) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  while (true) {
    LumpedParams p;
    p.J2 = 0.2 + 0.8 * u(rng);
    p.X2 = 0.5 + 2.0 * u(rng);
    p.Y2 = -0.5 + 1.0 * u(rng);
    p.J1 = p.J2 + 0.5 + 4.0 * u(rng);
    p.X1 = 2.0 + 5.0 * u(rng);
    p.Y1 = -0.5 + 1.0 * u(rng);
    if ((p.X2 * p.X2 + p.Y2 * p.Y2) / p.J2 < 0.8 * (p.J1 - p.J2) / (L1 * L1)) return p;
  }
}

// 1e-9 relative: MuJoCo and the closed form differ only by floating-point rounding (MuJoCo composes
// spatial inertias; the closed form uses the lumped sums), both well below 1e-12 of the torque scale.
TEST(MujocoVsClosedForm, InverseDynamicsRandomStatesAndParameters) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> s(-1.0, 1.0);
  for (int k = 0; k < 50; ++k) {
    LegParams lp;
    lp.L1 = 0.36 + 0.1 * (s(rng) + 1) / 2;
    lp.exo = RandomValid(rng, lp.L1);
    lp.human = RandomValid(rng, lp.L1);
    lp.passive = k % 2 ? PassiveModel::kRiener1999 : PassiveModel::kNone;
    plant.SetParams(lp);
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector2d q(0.2 + 0.9 * s(rng), -1.0 + 1.0 * s(rng));
      const Eigen::Vector2d qd(3 * s(rng), 4 * s(rng)), qdd(20 * s(rng), 30 * s(rng));
      const Eigen::Vector2d mj = plant.InverseDynamics(q, qd, qdd);
      const Eigen::Vector2d cf = ActuatorTorque(lp, q, qd, qdd);
      const double scale = std::max(1.0, cf.norm());
      EXPECT_NEAR(mj[0], cf[0], 1e-9 * scale) << "sample " << k << "/" << i;
      EXPECT_NEAR(mj[1], cf[1], 1e-9 * scale) << "sample " << k << "/" << i;
      // And the identification regressor: Y(q, qd, qdd) * phi_HR + P = MuJoCo.
      const Eigen::Vector2d reg = FullRegressor(lp.L1, lp.g, q, qd, qdd) * ToVector(lp.Total());
      const Eigen::Vector2d P = cf - RigidInverseDynamics(lp.Total(), lp.L1, lp.g, q, qd, qdd);
      EXPECT_NEAR(mj[0], reg[0] + P[0], 1e-9 * scale);
      EXPECT_NEAR(mj[1], reg[1] + P[1], 1e-9 * scale);
    }
  }
}

// The exo-only model with exo parameters equals the closed form with the human absent.
TEST(MujocoVsClosedForm, ExoOnlyModel) {
  Plant plant(ShippedModelPath("exowheel_exo_only.xml"));
  LegParams lp;
  lp.L1 = 0.41;
  lp.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  plant.SetParams(lp);
  const Eigen::Vector2d q(0.5, -0.7), qd(1.2, -0.4), qdd(-3, 7);
  const Eigen::Vector2d mj = plant.InverseDynamics(q, qd, qdd);
  const Eigen::Vector2d cf = ActuatorTorque(lp, q, qd, qdd);
  EXPECT_NEAR(mj[0], cf[0], 1e-9 * cf.norm());
  EXPECT_NEAR(mj[1], cf[1], 1e-9 * cf.norm());
}

// Forward simulation: MuJoCo's accelerations under a torque equal the closed form's
// M^-1 (tau - V - G - P) (checks the model, gravity direction and the applied passive torque).
TEST(MujocoVsClosedForm, ForwardDynamicsAgree) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  LegParams lp;
  lp.L1 = 0.41;
  lp.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  lp.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
  lp.passive = PassiveModel::kRiener1999;
  plant.SetParams(lp);
  const Eigen::Vector2d q(0.4, -0.9), qd(0.5, -1.0), tau(30, -5);
  plant.Reset(q, qd);
  plant.Step(tau);
  const Eigen::Vector2d rhs = tau - (ActuatorTorque(lp, q, qd, Eigen::Vector2d::Zero()));
  const Eigen::Vector2d acc = MassMatrix(lp.Total(), lp.L1, q[1]).ldlt().solve(rhs);
  EXPECT_NEAR(plant.qdd()[0], acc[0], 1e-8 * (1 + acc.norm()));
  EXPECT_NEAR(plant.qdd()[1], acc[1], 1e-8 * (1 + acc.norm()));
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// Table 4's S3 has no realization of its own (empty m2 window); the plant lends thigh inertia from the
// exoskeleton so that the sum, and hence every joint torque, is exactly the printed one.
TEST(MujocoVsClosedForm, UnrealizableHumanIsSplitWithExactTotal) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  LegParams lp;
  lp.L1 = 0.43;
  lp.exo = {3.21, 0.77, 3.99, 1.78, 0.12, 0.18};
  lp.human = LumpedParams{1.50, 0.40, 4.40, 1.50, -0.50, 0.42};
  lp.passive = PassiveModel::kRiener1999;
  ASSERT_NO_THROW(plant.SetParams(lp));
  const Eigen::Vector2d q(0.3, -1.2), qd(1.0, -2.0), qdd(4.0, -6.0);
  const Eigen::Vector2d mj = plant.InverseDynamics(q, qd, qdd);
  const Eigen::Vector2d cf = ActuatorTorque(lp, q, qd, qdd);
  EXPECT_NEAR(mj[0], cf[0], 1e-9 * cf.norm());
  EXPECT_NEAR(mj[1], cf[1], 1e-9 * cf.norm());
  // Every body physical.
  for (int b = 1; b < plant.model()->nbody; ++b) {
    if (std::string(mj_id2name(plant.model(), mjOBJ_BODY, b)) == "seat") continue;
    EXPECT_GT(plant.model()->body_mass[b], 0.0);
    EXPECT_GT(plant.model()->body_inertia[3 * b + 1], 0.0);
  }
}

// A human set that even the combined system cannot realize is rejected with a clear error.
TEST(MujocoVsClosedForm, RejectsUnrealizableSets) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  LegParams lp;
  lp.L1 = 0.41;
  lp.exo = {0.80, 0.74, 3.85, 1.74, 0.15, 0.16};
  try {
    plant.SetParams(lp);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no physically consistent realization"), std::string::npos);
  }
}

}  // namespace
}  // namespace exotwin
