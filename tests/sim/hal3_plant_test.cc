// The HAL-3 one-joint plant: pendulum dynamics of HKS05 eq. 4/15, the strain-gauge torque, divergence.
#include "sim/hal3_plant.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/subjects.h"

namespace exotwin {
namespace {

// Small swings of the relaxed, frictionless link: period 2 pi sqrt(I / mgl).
TEST(Hal3Plant, SmallSwingPeriodMatchesPendulum) {
  Hal3Plant plant;
  Hal3PlantParams p = Hal3ParamsForSubject(PresetSubject("S1"));
  p.R = p.C = 0;
  plant.SetParams(p);
  plant.Reset(0.05, 0.0);
  std::vector<double> down;  // times of downward zero crossings
  double last = plant.th();
  for (int k = 0; k < 6000 && down.size() < 3; ++k) {
    plant.Step(0.0, 0.0);
    if (last > 0 && plant.th() <= 0) down.push_back(plant.time());
    last = plant.th();
  }
  ASSERT_EQ(down.size(), 3u);
  const double period = 0.5 * (down[2] - down[0]);
  const double expect = 2 * M_PI * std::sqrt(p.I() / p.mgl());
  EXPECT_NEAR(period, expect, 0.01 * expect);
}

// Holding the leg still at th with the motor: the strain gauge carries the human's gravity moment.
TEST(Hal3Plant, InteractionTorqueIsWhatHalPassesToTheLeg) {
  Hal3Plant plant;
  const Hal3PlantParams p = Hal3ParamsForSubject(PresetSubject("S1"));
  plant.SetParams(p);
  const double th = 0.6;
  plant.Reset(th, 0.0);
  const double hold = p.mgl() * std::sin(th);
  plant.Step(hold, 0.0);
  EXPECT_NEAR(plant.thdd(), 0.0, 1e-6);
  EXPECT_NEAR(plant.interaction_torque(), (p.mgl() - p.hal_mgl()) * std::sin(th), 1e-6);
  // The muscles hold it instead: HAL passes nothing but its own weight compensation.
  plant.Reset(th, 0.0);
  plant.Step(p.hal_mgl() * std::sin(th), (p.mgl() - p.hal_mgl()) * std::sin(th));
  EXPECT_NEAR(plant.interaction_torque(), 0.0, 1e-6);
}

TEST(Hal3Plant, NonFiniteTorqueIsASimulationError) {
  Hal3Plant plant;
  plant.Reset(0.0, 0.0);
  EXPECT_THROW(plant.Step(NAN, 0.0), SimulationError);
  EXPECT_THROW(plant.Step(0.0, INFINITY), SimulationError);
}

}  // namespace
}  // namespace exotwin
