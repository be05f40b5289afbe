// Divergence is an error: the plant stops with SimulationError naming the time and the cause.
#include "sim/plant.h"

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

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

}  // namespace
}  // namespace exotwin
