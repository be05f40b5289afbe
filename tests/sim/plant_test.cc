// Divergence is an error: the plant stops with SimulationError naming the time and the cause.
#include "sim/plant.h"

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

#include "model/one_joint.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

std::unique_ptr<Plant> MakePlant() {
  auto p = std::make_unique<Plant>(ShippedModelPath("leg_exowheel.xml"));
  p->SetParams(SubjectLegParams(PresetSubject("S1")));
  p->Reset({0.3, -0.5}, {0, 0}, 0.0);
  return p;
}

std::string StepUntilError(Plant& p, const Eigen::Vector2d& tau, const Eigen::Vector2d& ext, double* t_err) {
  for (int i = 0; i < 5000; ++i) {
    try {
      p.Step(tau, ext);
    } catch (const SimulationError& e) {
      *t_err = e.time();
      return e.what();
    }
  }
  return "";
}

TEST(PlantDivergence, NaNTorqueCommand) {
  auto pp = MakePlant();
  Plant& p = *pp;
  for (int i = 0; i < 10; ++i) p.Step({1, 1});
  double t = -1;
  const std::string msg = StepUntilError(p, {std::numeric_limits<double>::quiet_NaN(), 0}, {0, 0}, &t);
  EXPECT_NE(msg.find("non-finite torque command"), std::string::npos) << msg;
  EXPECT_NEAR(t, 0.010, 1e-9);
  EXPECT_NE(msg.find("t = 0.01"), std::string::npos) << msg;
}

TEST(PlantDivergence, InfiniteExternalTorque) {
  auto pp = MakePlant();
  Plant& p = *pp;
  double t = -1;
  const std::string msg = StepUntilError(p, {0, 0}, {0, std::numeric_limits<double>::infinity()}, &t);
  EXPECT_NE(msg.find("non-finite torque command"), std::string::npos) << msg;
  EXPECT_EQ(t, 0.0);
}

// A finite but absurd external torque makes the state blow up: MuJoCo's own divergence detection
// (bad qacc/qvel/qpos warning, which resets the data) or our non-finite check must stop the run.
TEST(PlantDivergence, ExplodingStateIsCaught) {
  auto pp = MakePlant();
  Plant& p = *pp;
  double t = -1;
  const std::string msg = StepUntilError(p, {0, 0}, {1e300, -1e300}, &t);
  ASSERT_FALSE(msg.empty()) << "the run did not stop";
  EXPECT_NE(msg.find("simulation diverged at t ="), std::string::npos) << msg;
  EXPECT_TRUE(msg.find("MuJoCo warning") != std::string::npos || msg.find("non-finite state") != std::string::npos)
      << msg;
}

// The shipped EXOwheel model: with a human the leg + exoskeleton, else the exoskeleton alone.
TEST(ExowheelMjcfPath, ChoosesTheModelWithHumanBodiesOnlyWithAHuman) {
  EXPECT_EQ(ExowheelMjcfPath(true), ShippedModelPath("leg_exowheel.xml"));
  EXPECT_EQ(ExowheelMjcfPath(false), ShippedModelPath("exowheel_exo_only.xml"));
  EXPECT_TRUE(Plant(ExowheelMjcfPath(true)).has_human_bodies());
  EXPECT_FALSE(Plant(ExowheelMjcfPath(false)).has_human_bodies());
}

// HoldHip: a one-joint device embedded in the two-link model (model/one_joint.h) and driven forward.
// Reference: HKS05 eq. 4 without friction, I qdd + mgl sin q = tau, integrated by the scheme MuJoCo's
// Euler uses (qd += h qdd; q += h qd). The knee follows it to 1e-6 rad over 2 s of a 1.5 N m swing
// (the held hip's coupling is ~1e-8 of the knee's acceleration); the hip stays at exactly 0.
TEST(PlantHoldHip, TheKneeFollowsHks05Eq4AndTheHipStaysAtZero) {
  OneJointModel m;
  m.device = {0.168875, 3.3133};  // the DFKI pendulum's nominal point mass
  const LegParams params = EmbedOneJointModel(m, 9.81, {});
  Plant plant(ExowheelMjcfPath(false));
  plant.SetParams(params);
  plant.FreeJointsAndTorque();
  plant.HoldHip();
  EXPECT_TRUE(plant.hip_held());
  plant.Reset({0.7, 0.4}, {-1.0, 0.3});  // the hip's state given is ignored
  EXPECT_EQ(plant.q()[0], 0.0);
  double q = 0.4, qd = 0.3, worst = 0;
  const double h = plant.timestep();
  for (int i = 0; i < 2000; ++i) {
    const double tau = 1.5 * std::sin(2 * M_PI * 0.8 * plant.time()) + 4.0 * (i > 1000);
    plant.Step({2.0, tau});  // a hip torque too: held anyway
    qd += h * (tau - m.device.mgl * std::sin(q)) / m.device.I;
    q += h * qd;
    worst = std::max(worst, std::abs(plant.q()[1] - q));
    ASSERT_EQ(plant.q()[0], 0.0);
    ASSERT_EQ(plant.qd()[0], 0.0);
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(std::abs(q - 0.4), 0.5);  // the knee swung
  // Without the hold the hip swings and the knee leaves the one-joint law.
  Plant free_hip(ExowheelMjcfPath(false));
  free_hip.SetParams(params);
  free_hip.FreeJointsAndTorque();
  free_hip.Reset({0.0, 0.4}, {0.0, 0.3});
  for (int i = 0; i < 500; ++i) free_hip.Step({2.0, 0.0});
  EXPECT_GT(std::abs(free_hip.q()[0]), 0.1);
}

}  // namespace
}  // namespace exotwin
