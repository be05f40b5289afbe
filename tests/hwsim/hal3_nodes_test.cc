// HAL-3 knee node and EMG amplifier node on the virtual bus: frames, sensor resolution, driver.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hwsim/emg_node.h"
#include "hwsim/hal3_knee_node.h"
#include "hwsim/virtual_can_bus.h"
#include "protocol/messages.h"

namespace exotwin::hwsim {
namespace {

TEST(Hal3KneeNode, StatusFramesCarryPotentiometerAndStrainGauge) {
  VirtualCanBus bus;
  auto* ctrl = bus.AddNode("ctrl", {msg::kIdHalKneeStatus});
  auto* node_ep = bus.AddNode("knee", {msg::kIdHalKneeCommand});
  Hal3KneeNodeSpec spec;
  spec.pot.noise = 0;
  spec.strain.noise = 0;
  Hal3KneeNode node(spec, node_ep, 1);
  ASSERT_EQ(node.Sample(0.0, 0.5, -3.21), CanStatus::kOk);
  bus.AdvanceTo(0.001);
  CanFrame f;
  ASSERT_EQ(ctrl->Receive(&f), CanStatus::kOk);
  msg::HalKneeStatus s;
  ASSERT_TRUE(msg::Decode(f, &s));
  const double lsb = spec.pot.range / std::ldexp(1.0, spec.pot.adc_bits);
  EXPECT_NEAR(s.angle, 0.5, 0.5 * lsb + 1e-4);  // ADC LSB + frame LSB
  EXPECT_NEAR(s.torque, -3.21, 0.01);
}

// Hal3KneeNodeSpec::torque_sensor_skew: 0 pairs the potentiometer and the strain gauge of one
// instant; k = 2 sends the strain gauge of two samples before (the first reading held until then).
TEST(Hal3KneeNode, StrainGaugeSkewIsAKStepDelay) {
  for (int k : {0, 2}) {
    VirtualCanBus bus;
    auto* ctrl = bus.AddNode("ctrl", {msg::kIdHalKneeStatus});
    auto* node_ep = bus.AddNode("knee", {msg::kIdHalKneeCommand});
    Hal3KneeNodeSpec spec;
    spec.pot.noise = 0;
    spec.strain.noise = 0;
    spec.torque_sensor_skew = k;
    Hal3KneeNode node(spec, node_ep, 1);
    for (int i = 0; i < 6; ++i) {
      ASSERT_EQ(node.Sample(i * 1e-3, 0.1 * i, 1.0 * i), CanStatus::kOk);
      bus.AdvanceTo(i * 1e-3 + 0.9e-3);
      CanFrame f;
      ASSERT_EQ(ctrl->Receive(&f), CanStatus::kOk);
      msg::HalKneeStatus s;
      ASSERT_TRUE(msg::Decode(f, &s));
      EXPECT_NEAR(s.angle, 0.1 * i, 1e-3) << "k " << k << " sample " << i;
      EXPECT_NEAR(s.torque, 1.0 * std::max(i - k, 0), 0.011) << "k " << k << " sample " << i;
    }
  }
}

TEST(Hal3KneeNode, CommandFramesDriveTheMotorAndWatchdogCuts) {
  VirtualCanBus bus;
  auto* ctrl = bus.AddNode("ctrl", {msg::kIdHalKneeStatus});
  auto* node_ep = bus.AddNode("knee", {msg::kIdHalKneeCommand});
  Hal3KneeNode node(Hal3KneeNodeSpec{}, node_ep, 1);
  msg::HalKneeCommand c;
  c.torque = 80.0;  // beyond the 60 N m limit
  c.enable = true;
  ASSERT_EQ(ctrl->Send(msg::Encode(c)), CanStatus::kOk);
  bus.AdvanceTo(0.001);
  double tau = 0;
  for (int k = 1; k <= 10; ++k) tau = node.Applied(k * 1e-3, 1e-3);
  EXPECT_NEAR(tau, 60.0, 1e-6);
  for (int k = 11; k <= 60; ++k) tau = node.Applied(k * 1e-3, 1e-3);  // no commands for 50 ms
  EXPECT_NEAR(tau, 0.0, 1e-9);  // current loop decays after the cut
  EXPECT_TRUE(node.driver().watchdog_tripped());
}

TEST(EmgNode, OneFramePerSampleWithAmplifiedVolts) {
  VirtualCanBus bus;
  auto* ctrl = bus.AddNode("ctrl", {msg::kIdEmgSamples});
  auto* amp_ep = bus.AddNode("emg", {msg::kIdControllerHeartbeat});
  EmgNode node(EmgAmplifierSpec{}, amp_ep);
  int frames = 0;
  double max_v = 0;
  for (int k = 0; k < 200; ++k) {
    const double x = 1e-3 * std::sin(2 * M_PI * 100 * k * 1e-3);  // 1 mV at 100 Hz: in band
    ASSERT_EQ(node.Sample(k * 1e-3, {x, x, x, x, x}), CanStatus::kOk);
    bus.AdvanceTo((k + 1) * 1e-3);
    CanFrame f;
    while (ctrl->Receive(&f) == CanStatus::kOk) {
      msg::EmgSamples e;
      ASSERT_TRUE(msg::Decode(f, &e));
      EXPECT_EQ(e.counter, frames & 0x0f);
      if (frames > 100) max_v = std::max(max_v, std::abs(e.volts[1]));
      ++frames;
    }
  }
  EXPECT_EQ(frames, 200);
  EXPECT_NEAR(max_v, 1.0, 0.1);  // gain 1000
}

}  // namespace
}  // namespace exotwin::hwsim
