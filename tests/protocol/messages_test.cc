// The codec against hand-packed bytes, saturation, NaN handling and ID priorities.
#include "protocol/messages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace exotwin::msg {
namespace {

std::vector<int> Bytes(const CanFrame& f) { return std::vector<int>(f.data.begin(), f.data.begin() + f.dlc); }

TEST(Messages, JointCommandBytes) {
  // 1.23 N m / 0.01 = 123 = 0x007B little-endian; counter 7; enable bit 0.
  CanFrame f = Encode(JointCommand{Joint::kKnee, 1.23, 7, true});
  EXPECT_EQ(f.id, 0x101);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x7B, 0x00, 0x07, 0x01}));
  // -1.23 N m -> -123 = 0xFF85.
  f = Encode(JointCommand{Joint::kHip, -1.23, 255, false});
  EXPECT_EQ(f.id, 0x100);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x85, 0xFF, 0xFF, 0x00}));
  JointCommand c;
  ASSERT_TRUE(Decode(f, &c));
  EXPECT_EQ(c.joint, Joint::kHip);
  EXPECT_DOUBLE_EQ(c.torque, -1.23);
  EXPECT_EQ(c.counter, 255);
  EXPECT_FALSE(c.enable);
}

TEST(Messages, JointStatusBytes) {
  // -1 rad / 1e-6 = -1000000 = 0xFFF0BDC0; 12.345 N m / 0.015 = 823 = 0x0337.
  CanFrame f = Encode(JointStatus{Joint::kKnee, -1.0, 12.345, kStatusEnabled | kStatusEncoderFault, 42});
  EXPECT_EQ(f.id, 0x181);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0xC0, 0xBD, 0xF0, 0xFF, 0x37, 0x03, 0x09, 42}));
  JointStatus s;
  ASSERT_TRUE(Decode(f, &s));
  EXPECT_EQ(s.joint, Joint::kKnee);
  EXPECT_NEAR(s.angle, -1.0, 1e-12);
  EXPECT_NEAR(s.torque, 823 * 0.015, 1e-12);
  EXPECT_EQ(s.flags, 0x09);
  EXPECT_EQ(s.counter, 42);
}

TEST(Messages, EmgPacking) {
  // Channel 0 = +1 LSB, channel 1 = -1 LSB (0xFFF), counter 3: word = 0x3000000000FFF001.
  EmgSamples e;
  e.volts = {kEmgScale, -kEmgScale, 0, 0, 0};
  e.counter = 3;
  CanFrame f = Encode(e);
  EXPECT_EQ(f.id, 0x200);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x01, 0xF0, 0xFF, 0x00, 0x00, 0x00, 0x00, 0x30}));
  // Saturation: +-10 V -> +2047 / -2048 LSB.
  e.volts = {10, -10, 1.0, -1.0, 0.0049};
  ASSERT_TRUE(Decode(Encode(e), &e));
  EXPECT_DOUBLE_EQ(e.volts[0], 2047 * 5.0 / 2048);
  EXPECT_DOUBLE_EQ(e.volts[1], -5.0);
  EXPECT_DOUBLE_EQ(e.volts[2], 410 * 5.0 / 2048);  // 409.6 LSB -> 410 LSB
  EXPECT_DOUBLE_EQ(e.volts[3], -410 * 5.0 / 2048);
  EXPECT_DOUBLE_EQ(e.volts[4], 2 * kEmgScale);
}

TEST(Messages, HeartbeatAndHal) {
  CanFrame f = Encode(ControllerHeartbeat{2, 0x0281, 7, 200});
  EXPECT_EQ(f.id, 0x010);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x02, 0x81, 0x02, 0x07, 200}));
  f = Encode(HalKneeStatus{-0.5, 3.21, kStatusWatchdog, 9});
  // -0.5 / 1e-4 = -5000 = 0xEC78; 321 = 0x0141.
  EXPECT_EQ(f.id, 0x190);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x78, 0xEC, 0x41, 0x01, 0x02, 9}));
  f = Encode(HalKneeCommand{-2.5, 1, true});
  EXPECT_EQ(f.id, 0x110);
  EXPECT_EQ(Bytes(f), (std::vector<int>{0x06, 0xFF, 0x01, 0x01}));  // -250 = 0xFF06
}

TEST(Messages, SaturationAndNaN) {
  JointCommand c;
  ASSERT_TRUE(Decode(Encode(JointCommand{Joint::kHip, 1000.0, 0, true}), &c));
  EXPECT_DOUBLE_EQ(c.torque, 327.67);
  ASSERT_TRUE(Decode(Encode(JointCommand{Joint::kHip, -1000.0, 0, true}), &c));
  EXPECT_DOUBLE_EQ(c.torque, -327.68);
  ASSERT_TRUE(Decode(Encode(JointCommand{Joint::kHip, std::nan(""), 0, true}), &c));
  EXPECT_EQ(c.torque, 0.0);
  JointStatus s;
  ASSERT_TRUE(Decode(Encode(JointStatus{Joint::kHip, INFINITY, -INFINITY, 0, 0}), &s));
  EXPECT_DOUBLE_EQ(s.angle, 2147483647 * 1e-6);
  EXPECT_DOUBLE_EQ(s.torque, -32768 * 0.015);
}

TEST(Messages, RoundTripWithinHalfAnLsb) {
  std::mt19937_64 gen(3);
  auto uni = [&](double lo, double hi) { return lo + (hi - lo) * (gen() >> 11) * (1.0 / 9007199254740992.0); };
  for (int k = 0; k < 1000; ++k) {
    JointStatus in{k % 2 ? Joint::kHip : Joint::kKnee, uni(-3.2, 3.2), uni(-120, 120), 0, uint8_t(k)}, out;
    ASSERT_TRUE(Decode(Encode(in), &out));
    EXPECT_NEAR(out.angle, in.angle, 0.5e-6 + 1e-15);
    EXPECT_NEAR(out.torque, in.torque, 0.0075 + 1e-12);
    EXPECT_EQ(out.joint, in.joint);
    EXPECT_EQ(out.counter, in.counter);
  }
}

TEST(Messages, DecodeRejectsOtherFrames) {
  CanFrame f = Encode(JointStatus{});
  JointCommand c;
  EXPECT_FALSE(Decode(f, &c));
  JointStatus s;
  CanFrame shortf = f;
  shortf.dlc = 7;
  EXPECT_FALSE(Decode(shortf, &s));
  CanFrame err = f;
  err.error = true;
  EXPECT_FALSE(Decode(err, &s));
  EXPECT_TRUE(Decode(f, &s));
}

TEST(Messages, SafetyCriticalIdsWinArbitration) {
  // Heartbeat/faults beat torque commands, which beat measurements, which beat EMG.
  EXPECT_LT(kIdControllerHeartbeat, kIdJointCommandHip);
  EXPECT_LT(kIdJointCommandKnee, kIdHalKneeCommand);
  EXPECT_LT(kIdHalKneeCommand, kIdJointStatusHip);
  EXPECT_LT(kIdJointStatusKnee, kIdHalKneeStatus);
  EXPECT_LT(kIdHalKneeStatus, kIdEmgSamples);
  EXPECT_LE(kIdEmgSamples, 0x7FF);
}

}  // namespace
}  // namespace exotwin::msg
