// EXOwheel joint-module node (hwsim/joint_module.h): one sampling instant for encoder and torque
// sensor, and JointModuleSpec::torque_sensor_skew as a k-sample delay of one of them.
#include "hwsim/joint_module.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hwsim/virtual_can_bus.h"

namespace exotwin::hwsim {
namespace {

struct Frame {
  double angle, torque;
};

// Sends n frames, sample i carrying the true angle 0.01 i rad and the true motor torque i N m
// (tau_R; the sensor reads -tau_R), and returns what the controller receives.
std::vector<Frame> SendFrames(int skew, int n) {
  VirtualCanBus bus;
  auto* ctrl = bus.AddNode("ctrl", {msg::kIdJointStatusHip});
  auto* ep = bus.AddNode("hip", {msg::kIdJointCommandHip});
  JointModuleSpec spec;
  spec.torque_sensor.repeatability_fs = 0;
  spec.torque_sensor.nonlinearity_fs = 0;
  spec.torque_sensor_skew = skew;
  JointModule module(spec, ep, 3);
  std::vector<Frame> out;
  for (int i = 0; i < n; ++i) {
    const double t = i * 1e-3;
    EXPECT_EQ(module.Sample(t, 0.01 * i, static_cast<double>(i)), CanStatus::kOk);
    bus.AdvanceTo(t + 0.9e-3);
    CanFrame f;
    EXPECT_EQ(ctrl->Receive(&f), CanStatus::kOk);
    msg::JointStatus s;
    EXPECT_TRUE(msg::Decode(f, &s));
    out.push_back({s.angle, s.torque});
  }
  return out;
}

// Skew 0: the frame of sample i carries the angle and the torque of sample i.
TEST(JointModule, EncoderAndTorqueSensorShareOneInstant) {
  const std::vector<Frame> f = SendFrames(0, 8);
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(f[i].angle, 0.01 * i, 1e-4) << i;
    EXPECT_NEAR(f[i].torque, -i, 0.02) << i;
  }
}

// Skew k > 0: the torque is k samples older than the angle (the first torque held until then);
// k < 0: the angle is |k| samples older than the torque.
TEST(JointModule, SkewOfKSamplesIsAKStepDelay) {
  for (int k : {1, 3}) {
    const std::vector<Frame> f = SendFrames(k, 10);
    for (int i = 0; i < 10; ++i) {
      EXPECT_NEAR(f[i].angle, 0.01 * i, 1e-4) << "k " << k << " sample " << i;
      EXPECT_NEAR(f[i].torque, -std::max(i - k, 0), 0.02) << "k " << k << " sample " << i;
    }
  }
  const std::vector<Frame> f = SendFrames(-2, 10);
  for (int i = 0; i < 10; ++i) {
    EXPECT_NEAR(f[i].angle, 0.01 * std::max(i - 2, 0), 1e-4) << "k -2 sample " << i;
    EXPECT_NEAR(f[i].torque, -i, 0.02) << "k -2 sample " << i;
  }
}

}  // namespace
}  // namespace exotwin::hwsim
