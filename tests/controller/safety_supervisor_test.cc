// Tests of controller/safety_supervisor.h: every fault path reaches the right state on the tick the
// condition first appears, faults latch, states only go up until Reset(), and no input (NaN, inf)
// ever yields a non-finite or out-of-range torque.
#include "controller/safety_supervisor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/error.h"
#include "core/units.h"

namespace exotwin::controller {
namespace {


// Stable bus values.
static_assert(static_cast<int>(SafetyState::kRunning) == 0);
static_assert(static_cast<int>(SafetyState::kSafeDamping) == 1);
static_assert(static_cast<int>(SafetyState::kSafeTorqueOff) == 2);
static_assert(static_cast<int>(FaultCode::kJointLimit) == 1);
static_assert(static_cast<int>(FaultCode::kOverspeed) == 2);
static_assert(static_cast<int>(FaultCode::kSensorTorqueLimit) == 3);
static_assert(static_cast<int>(FaultCode::kCommandTorqueLimit) == 4);
static_assert(static_cast<int>(FaultCode::kNonFiniteCommand) == 5);
static_assert(static_cast<int>(FaultCode::kNonFiniteMeasurement) == 6);
static_assert(static_cast<int>(FaultCode::kStaleFrame) == 7);
static_assert(static_cast<int>(FaultCode::kStuckCounter) == 8);
static_assert(static_cast<int>(FaultCode::kEmergencyStop) == 9);

uint32_t Bit(FaultCode f) { return 1u << static_cast<int>(f); }

// Healthy inputs, counters advancing every tick.
struct Feed {
  SafetyInput in;
  uint32_t counter = 0;
  Feed() {
    in.hip = {45 * kRadPerDeg, 0.5, 3.0, 2.0, 0.001, 0};
    in.knee = {-40 * kRadPerDeg, -0.8, -1.0, -1.5, 0.001, 0};
  }
  SafetyInput& Next() {
    ++counter;
    in.hip.counter = counter;
    in.knee.counter = counter + 1000;
    return in;
  }
};

class SafetyTest : public ::testing::Test {
 protected:
  SafetyConfig cfg = SafetyConfig::Default();
  SafetySupervisor sup{cfg};
  Feed feed;
  // Runs 5 healthy ticks first, so that a fault is known to appear on one specific tick.
  void WarmUp() {
    for (int i = 0; i < 5; ++i) {
      const SafetyOutput o = sup.Update(feed.Next());
      ASSERT_EQ(o.state, SafetyState::kRunning);
      ASSERT_EQ(o.fault_mask, 0u);
    }
  }
  // Applies one faulty tick and checks state, code, joint and the torque of that very tick.
  void ExpectTrips(SafetyState state, FaultCode code, uint32_t joint) {
    const SafetyOutput o = sup.Update(feed.in);
    EXPECT_EQ(o.state, state);
    EXPECT_TRUE(o.fault_mask & Bit(code)) << "mask " << o.fault_mask;
    EXPECT_EQ(o.first_fault, code);
    EXPECT_EQ(o.joint_mask & joint, joint);
    EXPECT_TRUE(std::isfinite(o.tau_hip) && std::isfinite(o.tau_knee));
    if (state == SafetyState::kSafeTorqueOff) {
      EXPECT_EQ(o.tau_hip, 0.0);
      EXPECT_EQ(o.tau_knee, 0.0);
    } else if (state == SafetyState::kSafeDamping) {
      if (std::isfinite(feed.in.hip.qd)) {
        EXPECT_DOUBLE_EQ(o.tau_hip, -cfg.hip.damping * feed.in.hip.qd);
      }
      if (std::isfinite(feed.in.knee.qd)) {
        EXPECT_DOUBLE_EQ(o.tau_knee, -cfg.knee.damping * feed.in.knee.qd);
      }
    }
  }
};

TEST_F(SafetyTest, HealthyInputsPassTheCommandThrough) {
  WarmUp();
  const SafetyOutput o = sup.Update(feed.Next());
  EXPECT_EQ(o.tau_hip, 2.0);
  EXPECT_EQ(o.tau_knee, -1.5);
  EXPECT_EQ(o.first_fault, FaultCode::kNone);
}

TEST_F(SafetyTest, JointLimitWithMarginDamps) {
  WarmUp();
  feed.Next().knee.q = cfg.knee.q_max - cfg.knee.q_margin - 1e-6;  // just inside: fine
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kRunning);
  feed.Next().knee.q = cfg.knee.q_max - cfg.knee.q_margin + 1e-6;  // inside the margin: trip
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kJointLimit, kKneeBit);
}

TEST_F(SafetyTest, LowerJointLimitDamps) {
  WarmUp();
  feed.Next().hip.q = cfg.hip.q_min;
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kJointLimit, kHipBit);
}

TEST_F(SafetyTest, OverspeedDamps) {
  WarmUp();
  feed.Next().hip.qd = cfg.hip.qd_max * 1.001;
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kOverspeed, kHipBit);
}

TEST_F(SafetyTest, SensorTorqueLimitDamps) {
  WarmUp();
  feed.Next().knee.tau_sensor = -cfg.knee.tau_sensor_max - 0.1;
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kSensorTorqueLimit, kKneeBit);
}

TEST_F(SafetyTest, CommandTorqueLimitDamps) {
  WarmUp();
  feed.Next().hip.tau_cmd = cfg.hip.tau_cmd_max + 0.1;
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kCommandTorqueLimit, kHipBit);
}

TEST_F(SafetyTest, NonFiniteCommandOrSensorDamps) {
  WarmUp();
  feed.Next().knee.tau_cmd = std::numeric_limits<double>::quiet_NaN();
  ExpectTrips(SafetyState::kSafeDamping, FaultCode::kNonFiniteCommand, kKneeBit);
  SafetySupervisor s2(cfg);
  Feed f2;
  f2.Next().hip.tau_sensor = -INFINITY;
  const SafetyOutput o = s2.Update(f2.in);
  EXPECT_EQ(o.state, SafetyState::kSafeDamping);
  EXPECT_EQ(o.first_fault, FaultCode::kNonFiniteCommand);
}

TEST_F(SafetyTest, NonFiniteAngleOrVelocityTurnsTorqueOff) {
  WarmUp();
  feed.Next().hip.q = NAN;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kNonFiniteMeasurement, kHipBit);
  sup.Reset();
  feed.in.hip.q = 45 * kRadPerDeg;
  feed.Next().knee.qd = INFINITY;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kNonFiniteMeasurement, kKneeBit);
}

TEST_F(SafetyTest, BadAgeTurnsTorqueOff) {
  WarmUp();
  feed.Next().hip.age_s = NAN;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kNonFiniteMeasurement, kHipBit);
  sup.Reset();
  feed.Next().hip.age_s = -0.001;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kNonFiniteMeasurement, kHipBit);
}

TEST_F(SafetyTest, StaleFrameTurnsTorqueOff) {
  WarmUp();
  feed.Next().knee.age_s = cfg.max_age_s;  // at the threshold: still fine
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kRunning);
  feed.Next().knee.age_s = cfg.max_age_s + 1e-4;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kStaleFrame, kKneeBit);
}

TEST_F(SafetyTest, StuckCounterTurnsTorqueOffAfterAllowedRepeats) {
  WarmUp();
  feed.Next();
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kRunning);
  const uint32_t stuck = feed.in.hip.counter;
  for (int r = 1; r <= cfg.max_counter_repeats; ++r) {  // tolerated repeats
    feed.Next().hip.counter = stuck;
    EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kRunning) << r;
  }
  feed.Next().hip.counter = stuck;  // one more: stuck
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kStuckCounter, kHipBit);
}

TEST_F(SafetyTest, EmergencyStopTurnsTorqueOff) {
  WarmUp();
  feed.Next().emergency_stop = true;
  ExpectTrips(SafetyState::kSafeTorqueOff, FaultCode::kEmergencyStop, 0u);
}

TEST_F(SafetyTest, FaultsLatchStatesOnlyGoUpAndResetClears) {
  WarmUp();
  feed.Next().hip.qd = 10.0;  // overspeed
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kSafeDamping);
  feed.Next().hip.qd = 0.5;  // condition gone: still latched
  SafetyOutput o = sup.Update(feed.in);
  EXPECT_EQ(o.state, SafetyState::kSafeDamping);
  EXPECT_DOUBLE_EQ(o.tau_hip, -cfg.hip.damping * 0.5);
  feed.Next().emergency_stop = true;
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kSafeTorqueOff);
  feed.Next().emergency_stop = false;
  o = sup.Update(feed.in);
  EXPECT_EQ(o.state, SafetyState::kSafeTorqueOff);  // never goes down by itself
  EXPECT_EQ(o.first_fault, FaultCode::kOverspeed);
  EXPECT_EQ(o.fault_mask, Bit(FaultCode::kOverspeed) | Bit(FaultCode::kEmergencyStop));
  sup.Reset();
  o = sup.Update(feed.Next());
  EXPECT_EQ(o.state, SafetyState::kRunning);
  EXPECT_EQ(o.fault_mask, 0u);
  EXPECT_EQ(o.tau_hip, feed.in.hip.tau_cmd);
  feed.Next().hip.qd = 10.0;  // persisting condition trips again after reset
  EXPECT_EQ(sup.Update(feed.in).state, SafetyState::kSafeDamping);
}

TEST_F(SafetyTest, DampingTorqueIsClamped) {
  WarmUp();
  feed.Next().knee.qd = -100.0;  // overspeed, huge damping demand
  const SafetyOutput o = sup.Update(feed.in);
  EXPECT_EQ(o.state, SafetyState::kSafeDamping);
  EXPECT_EQ(o.tau_knee, cfg.knee.tau_damp_max);
}

TEST(SafetySupervisor, FuzzedNonFiniteInputsNeverGiveBadTorque) {
  const SafetyConfig cfg = SafetyConfig::Default();
  const double specials[] = {NAN, INFINITY, -INFINITY, 0.0, 1e308, -1e308, 0.3, -2.0};
  std::mt19937_64 rng(99);
  const double bound = std::max({cfg.hip.tau_cmd_max, cfg.knee.tau_cmd_max, cfg.hip.tau_damp_max,
                                 cfg.knee.tau_damp_max});
  for (int run = 0; run < 200; ++run) {
    SafetySupervisor sup(cfg);
    Feed feed;
    for (int tick = 0; tick < 50; ++tick) {
      SafetyInput& in = feed.Next();
      for (JointSafetyInput* j : {&in.hip, &in.knee}) {
        double* fields[] = {&j->q, &j->qd, &j->tau_sensor, &j->tau_cmd, &j->age_s};
        for (double* f : fields)
          if (rng() % 10 == 0) *f = specials[rng() % 8];
      }
      const SafetyOutput o = sup.Update(in);
      ASSERT_TRUE(std::isfinite(o.tau_hip) && std::isfinite(o.tau_knee));
      ASSERT_LE(std::abs(o.tau_hip), bound);
      ASSERT_LE(std::abs(o.tau_knee), bound);
      if (o.state != SafetyState::kRunning) {
        ASSERT_NE(o.fault_mask, 0u);
      }
    }
  }
}

TEST(SafetySupervisor, RejectsInconsistentConfig) {
  SafetyConfig c = SafetyConfig::Default();
  c.hip.q_margin = 2.0;  // margins overlap
  EXPECT_THROW(SafetySupervisor{c}, InputError);
  c = SafetyConfig::Default();
  c.knee.tau_cmd_max = 0;
  EXPECT_THROW(SafetySupervisor{c}, InputError);
  c = SafetyConfig::Default();
  c.max_age_s = NAN;
  EXPECT_THROW(SafetySupervisor{c}, InputError);
  c = SafetyConfig::Default();
  c.max_counter_repeats = -1;
  EXPECT_THROW(SafetySupervisor{c}, InputError);
}

}  // namespace
}  // namespace exotwin::controller
