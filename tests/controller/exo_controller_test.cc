// Tests of controller/exo_controller.h through its bus only (tests/controller/fake_can_bus.h): the
// joint modules are scripted JointStatus frames, and what the controller promises is read back from
// the JointCommand and ControllerHeartbeat frames it sends:
//  - start-up: zero torque and enable = false until both modules have reported, then enabled;
//    one command per joint per tick, the heartbeat at 100 Hz (every 10th tick) and at once on a fault;
//  - the torque for a known (held) state is tau = tau_ff + Kp (q_ref - q) + Kd (qd_ref - qd)
//    (Hwang & Jeon 2015 sec. 3.1), tau_ff = M qdd + V + G + P of the controller's model (HJ15 eq. 5-7);
//  - the safety supervisor (controller/safety_supervisor.h) reacts on the tick a condition appears:
//    a silent module or a stuck counter -> safe torque off (enable = false, 0 N m) after
//    max_age_s / max_counter_repeats; an out-of-range or invalid reading -> safe damping; latched.
// Ticks run at 1024 Hz so that tick times and ages are exact binary fractions.
#include "controller/exo_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "model/leg_dynamics.h"
#include "protocol/messages.h"
#include "tests/controller/fake_can_bus.h"

namespace exotwin::controller {
namespace {

using testing::FakeCanBus;
constexpr double kRate = 1024.0;               // Hz
constexpr double kDt = 1.0 / kRate;            // s, exact
constexpr double kCommandLsb = msg::kCommandTorqueScale;
uint32_t Bit(FaultCode f) { return 1u << static_cast<int>(f); }

// Hip and knee held at fixed references, modules scripted tick by tick.
struct Rig {
  FakeCanBus bus;
  ExoControllerConfig cfg;
  std::unique_ptr<ExoController> ctl;
  double q_ref[2] = {0.30, -0.50};  // rad
  double q[2] = {0.28, -0.47};      // rad, what the encoders report
  double tau_s[2] = {1.5, -2.0};    // N m, what the torque sensors report
  uint8_t flags[2] = {msg::kStatusEnabled, msg::kStatusEnabled};
  uint8_t counter[2] = {0, 0};
  bool advance_counter[2] = {true, true};
  int k = 0;  // next tick index

  explicit Rig(bool feedforward = false) {
    cfg.rate_hz = kRate;
    cfg.estimator.sample_rate_hz = kRate;
    cfg.feedforward = feedforward;
    cfg.model.exo = {0.35, 0.08, 1.2, 0.45, 0.05, 0.02};
    cfg.safety.max_age_s = 3 * kDt;
    Build();
  }
  void Build() {
    auto traj = std::make_shared<JointwiseTrajectory>(std::make_shared<HoldTrajectory>(q_ref[0]),
                                                      std::make_shared<HoldTrajectory>(q_ref[1]));
    ctl = std::make_unique<ExoController>(cfg, traj, &bus);
  }
  double t() const { return k * kDt; }
  // Joint j's status frame, received at the coming tick.
  void Status(int j) {
    msg::JointStatus s;
    s.joint = static_cast<msg::Joint>(j);
    s.angle = q[j];
    s.torque = tau_s[j];
    s.flags = flags[j];
    s.counter = counter[j];
    if (advance_counter[j]) ++counter[j];
    bus.ScriptMessage(t(), s);
  }
  // One tick: the modules that speak send their status first; returns what the controller sent.
  std::vector<CanFrame> Tick(bool hip = true, bool knee = true) {
    if (hip) Status(0);
    if (knee) Status(1);
    bus.ClearSent();
    bus.AdvanceTo(t());
    ctl->Tick(t());
    ++k;
    return bus.sent();
  }
  const ControllerTelemetry& tel() const { return ctl->telemetry(); }
};

// The joint commands of one tick's frames, indexed by joint; fails the test if one is missing.
std::array<msg::JointCommand, 2> Commands(const std::vector<CanFrame>& frames) {
  std::array<msg::JointCommand, 2> out;
  int n = 0;
  for (const CanFrame& f : frames) {
    msg::JointCommand c;
    if (msg::Decode(f, &c)) {
      out[static_cast<int>(c.joint)] = c;
      ++n;
    }
  }
  EXPECT_EQ(n, 2) << "one JointCommand per joint per tick";
  return out;
}
int Heartbeats(const std::vector<CanFrame>& frames, msg::ControllerHeartbeat* last = nullptr) {
  int n = 0;
  for (const CanFrame& f : frames) {
    msg::ControllerHeartbeat hb;
    if (msg::Decode(f, &hb)) {
      ++n;
      if (last) *last = hb;
    }
  }
  return n;
}
// The decoded angle the controller saw (the encoder's int32 x 1e-6 rad quantization).
double Quantized(double angle) {
  msg::JointStatus s, d;
  s.angle = angle;
  EXPECT_TRUE(msg::Decode(msg::Encode(s), &d));
  return d.angle;
}
void ExpectTorqueOff(const std::vector<CanFrame>& frames) {
  for (const msg::JointCommand& c : Commands(frames)) {
    EXPECT_FALSE(c.enable) << msg::JointName(c.joint);
    EXPECT_EQ(c.torque, 0.0) << msg::JointName(c.joint);
  }
}

TEST(ExoControllerBus, DisabledUntilBothModulesReportThenEnabled) {
  Rig rig;
  // Tick 0: nobody has spoken: zero torque, disabled, and the first heartbeat (state running).
  std::vector<CanFrame> sent = rig.Tick(false, false);
  ExpectTorqueOff(sent);
  msg::ControllerHeartbeat hb;
  ASSERT_EQ(Heartbeats(sent, &hb), 1);
  EXPECT_EQ(hb.state, 0);
  EXPECT_EQ(hb.fault_mask, 0);
  // Tick 1: the hip alone is not enough.
  ExpectTorqueOff(rig.Tick(true, false));
  EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning);
  // Tick 2: both modules have reported: enabled with the control torque.
  for (const msg::JointCommand& c : Commands(rig.Tick())) {
    EXPECT_TRUE(c.enable);
    EXPECT_NE(c.torque, 0.0);
  }
  EXPECT_EQ(rig.tel().frames_received, 3u);
}

TEST(ExoControllerBus, CommandCounterEveryTickHeartbeatEveryTenth) {
  Rig rig;
  std::vector<int> heartbeat_ticks;
  for (int i = 0; i < 35; ++i) {
    const std::vector<CanFrame> sent = rig.Tick();
    const auto cmd = Commands(sent);
    EXPECT_EQ(cmd[0].counter, static_cast<uint8_t>(i));
    EXPECT_EQ(cmd[1].counter, static_cast<uint8_t>(i));
    msg::ControllerHeartbeat hb;
    if (Heartbeats(sent, &hb)) {
      heartbeat_ticks.push_back(i);
      EXPECT_EQ(hb.counter, static_cast<uint8_t>(i));  // the frame counter shared with the commands
    }
  }
  EXPECT_EQ(heartbeat_ticks, (std::vector<int>{0, 10, 20, 30}));
  EXPECT_EQ(rig.tel().frames_sent, 35u * 2 + 4);
  EXPECT_EQ(rig.tel().send_failures, 0u);
}

TEST(ExoControllerBus, HeldStateTorqueIsThePdLaw) {
  Rig rig;
  for (int i = 0; i < 50; ++i) {
    const auto cmd = Commands(rig.Tick());
    // The angles do not move: the estimator starts at rest and its velocity stays exactly 0.
    for (int j = 0; j < 2; ++j) {
      const PdGains& g = j == 0 ? rig.cfg.hip : rig.cfg.knee;
      const double q = Quantized(rig.q[j]);
      const double expected = g.kp * (rig.q_ref[j] - q) + g.kd * (0.0 - 0.0);
      ASSERT_LT(std::abs(expected), g.tau_max);
      EXPECT_DOUBLE_EQ(rig.tel().tau_cmd[j], expected) << "joint " << j << " tick " << i;
      EXPECT_NEAR(cmd[j].torque, expected, kCommandLsb / 2 + 1e-12);
      EXPECT_TRUE(cmd[j].enable);
    }
  }
  EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning);
}

TEST(ExoControllerBus, HeldStateTorqueAddsTheModelFeedForward) {
  Rig rig(/*feedforward=*/true);
  for (int i = 0; i < 5; ++i) rig.Tick();
  const Vec2 ff = ActuatorTorque(rig.cfg.model, {rig.q_ref[0], rig.q_ref[1]}, {0, 0}, {0, 0});
  ASSERT_GT(std::abs(ff[0]), 1.0);  // the feed-forward matters
  const auto cmd = Commands(rig.Tick());
  for (int j = 0; j < 2; ++j) {
    const PdGains& g = j == 0 ? rig.cfg.hip : rig.cfg.knee;
    const double expected = ff[j] + g.kp * (rig.q_ref[j] - Quantized(rig.q[j]));
    EXPECT_NEAR(rig.tel().tau_cmd[j], expected, 1e-9) << "joint " << j;
    EXPECT_NEAR(cmd[j].torque, expected, kCommandLsb / 2 + 1e-9);
  }
}

// A command from outside (the Python twin, python/module_twin.cc) replaces PD + feed-forward: it is
// sent as given within the supervisor's limit, limited beyond it, and ignored while torque is off.
TEST(ExoControllerBus, CommandFromOutsideReplacesTheControlLawThroughTheSupervisor) {
  Rig rig(/*feedforward=*/true);
  const double none[2] = {0, 0};
  rig.bus.ClearSent();
  rig.bus.AdvanceTo(rig.t());
  rig.ctl->Tick(rig.t(), none);  // nobody has spoken: torque off whatever the command
  ++rig.k;
  ExpectTorqueOff(rig.bus.sent());
  for (int i = 0; i < 3; ++i) rig.Tick();
  const double given[2] = {3.25, -7.5};
  for (int j = 0; j < 2; ++j) rig.Status(j);
  rig.bus.ClearSent();
  rig.bus.AdvanceTo(rig.t());
  rig.ctl->Tick(rig.t(), given);
  ++rig.k;
  const auto cmd = Commands(rig.bus.sent());
  for (int j = 0; j < 2; ++j) {
    EXPECT_EQ(rig.tel().tau_cmd[j], given[j]) << "joint " << j;
    EXPECT_NEAR(cmd[j].torque, given[j], kCommandLsb / 2 + 1e-12);
    EXPECT_TRUE(cmd[j].enable);
  }
  EXPECT_EQ(rig.tel().ref[0].q, rig.q_ref[0]) << "the reference is still sampled";
  const double beyond[2] = {1e6, -1e6};
  for (int j = 0; j < 2; ++j) rig.Status(j);
  rig.bus.AdvanceTo(rig.t());
  rig.ctl->Tick(rig.t(), beyond);
  ++rig.k;
  EXPECT_LE(std::abs(rig.tel().tau_cmd[0]), rig.cfg.safety.hip.tau_cmd_max);
  EXPECT_LE(std::abs(rig.tel().tau_cmd[1]), rig.cfg.safety.knee.tau_cmd_max);
  EXPECT_GT(rig.cfg.safety.knee.tau_cmd_max, 0.0);
}

// max_age_s = 3 ticks; the counter watchdog alone would trip later.
TEST(ExoControllerBus, SilentModuleTorqueOffWhenItsFrameIsOlderThanMaxAge) {
  Rig rig;
  rig.cfg.safety.max_counter_repeats = 100;
  rig.Build();
  for (int i = 0; i < 20; ++i) rig.Tick();
  const int last = rig.k - 1;  // the knee's last frame came with this tick
  for (int i = 1; i <= 3; ++i) {  // age i ticks <= max_age_s: still running, knee angle held
    const std::vector<CanFrame> sent = rig.Tick(true, false);
    EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning) << i << " ticks after the last knee frame";
    EXPECT_EQ(rig.tel().age[1], i * kDt);
    for (const msg::JointCommand& c : Commands(sent)) EXPECT_TRUE(c.enable);
  }
  // 4 ticks: older than max_age_s: torque off on this very tick, heartbeat at once.
  const std::vector<CanFrame> sent = rig.Tick(true, false);
  ASSERT_EQ(rig.k - 1 - last, 4);
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeTorqueOff);
  EXPECT_EQ(rig.tel().safety.fault_mask, Bit(FaultCode::kStaleFrame));
  EXPECT_EQ(rig.tel().safety.joint_mask, static_cast<uint32_t>(kKneeBit));
  ExpectTorqueOff(sent);
  msg::ControllerHeartbeat hb;
  ASSERT_EQ(Heartbeats(sent, &hb), 1) << "a new fault is announced at once";
  EXPECT_EQ(hb.state, static_cast<uint8_t>(SafetyState::kSafeTorqueOff));
  EXPECT_EQ(hb.first_fault, static_cast<uint8_t>(FaultCode::kStaleFrame));
  EXPECT_EQ(hb.fault_mask, Bit(FaultCode::kStaleFrame));
  // Latched: the knee coming back does not re-enable the drives.
  for (int i = 0; i < 20; ++i) ExpectTorqueOff(rig.Tick());
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeTorqueOff);
}

// A module that keeps sending the same counter: tolerated on max_counter_repeats ticks, torque off
// on the next one, even though its frames are fresh.
TEST(ExoControllerBus, StuckCounterTorqueOffAfterMaxRepeats) {
  Rig rig;
  for (int i = 0; i < 20; ++i) rig.Tick();
  rig.advance_counter[0] = false;
  rig.Tick();  // the last new counter value
  for (int i = 1; i <= rig.cfg.safety.max_counter_repeats; ++i) {
    rig.Tick();
    EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning) << "repeat " << i;
  }
  const std::vector<CanFrame> sent = rig.Tick();
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeTorqueOff);
  EXPECT_EQ(rig.tel().safety.first_fault, FaultCode::kStuckCounter);
  EXPECT_EQ(rig.tel().safety.joint_mask, static_cast<uint32_t>(kHipBit));
  EXPECT_EQ(rig.tel().age[0], 0.0);  // fresh frames: the counter alone caught it
  ExpectTorqueOff(sent);
}

// An out-of-range torque-sensor reading: safe damping on the tick it arrives; the drives stay enabled
// with tau = clamp(-D qd, +-tau_damp_max) per joint (here the hip moves at about 0.5 rad/s).
TEST(ExoControllerBus, OutOfRangeReadingSafeDampingOnTheSameTick) {
  Rig rig;
  rig.cfg.hip.kp = 100;  // keeps the tracking torque below tau_cmd_max while the hip moves
  rig.Build();
  for (int i = 0; i < 200; ++i) {
    rig.q[0] = 0.25 + 0.5 * rig.t();
    rig.Tick();
  }
  ASSERT_EQ(rig.ctl->state(), SafetyState::kRunning);
  rig.tau_s[1] = rig.cfg.safety.knee.tau_sensor_max + 10.0;
  rig.q[0] = 0.25 + 0.5 * rig.t();
  const auto cmd = Commands(rig.Tick());
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeDamping);
  EXPECT_EQ(rig.tel().safety.fault_mask, Bit(FaultCode::kSensorTorqueLimit));
  EXPECT_EQ(rig.tel().safety.joint_mask, static_cast<uint32_t>(kKneeBit));
  const JointSafetyLimits* lim[2] = {&rig.cfg.safety.hip, &rig.cfg.safety.knee};
  for (int j = 0; j < 2; ++j) {
    const double qd = rig.tel().est[j].qd;
    const double expected = std::clamp(-lim[j]->damping * qd, -lim[j]->tau_damp_max, lim[j]->tau_damp_max);
    EXPECT_DOUBLE_EQ(rig.tel().tau_cmd[j], expected) << "joint " << j;
    EXPECT_NEAR(cmd[j].torque, expected, kCommandLsb / 2 + 1e-12);
    EXPECT_TRUE(cmd[j].enable);
  }
  EXPECT_NEAR(rig.tel().est[0].qd, 0.5, 0.01);
  EXPECT_LT(rig.tel().tau_cmd[0], -0.9);  // the damping torque opposes the motion
}

TEST(ExoControllerBus, AngleOutsideTheJointRangeSafeDamping) {
  Rig rig;
  for (int i = 0; i < 10; ++i) rig.Tick();
  rig.q[0] = rig.cfg.safety.hip.q_max;  // inside the mechanical range, beyond the margin
  rig.Tick();
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeDamping);
  EXPECT_EQ(rig.tel().safety.first_fault, FaultCode::kJointLimit);
  EXPECT_EQ(rig.tel().safety.joint_mask, static_cast<uint32_t>(kHipBit));
}

// A module flagging its torque sensor invalid: the reading is NaN to the controller -> damping.
TEST(ExoControllerBus, TorqueSensorFaultFlagSafeDamping) {
  Rig rig;
  for (int i = 0; i < 10; ++i) rig.Tick();
  rig.flags[1] |= msg::kStatusTorqueSensorFault;
  rig.Tick();
  EXPECT_TRUE(std::isnan(rig.tel().tau_sensor[1]));
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeDamping);
  EXPECT_EQ(rig.tel().safety.first_fault, FaultCode::kNonFiniteCommand);
}

// A module flagging its encoder invalid: its angle is not used (the estimate is held, as for a lost
// frame), so the angle ages like a silent module's: torque off once it is older than max_age_s.
TEST(ExoControllerBus, EncoderFaultFlagAgesTheAngleLikeASilentModule) {
  Rig rig;
  for (int i = 0; i < 10; ++i) rig.Tick();
  rig.flags[1] |= msg::kStatusEncoderFault;
  rig.q[1] = 0.7;  // garbage: must not reach the estimate
  for (int i = 1; i <= 3; ++i) {
    rig.Tick();
    EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning) << i;
    EXPECT_EQ(rig.tel().est[1].q, Quantized(-0.47));
  }
  ExpectTorqueOff(rig.Tick());
  EXPECT_EQ(rig.ctl->state(), SafetyState::kSafeTorqueOff);
  EXPECT_EQ(rig.tel().safety.first_fault, FaultCode::kStaleFrame);
  EXPECT_EQ(rig.tel().safety.joint_mask, static_cast<uint32_t>(kKneeBit));
}

// Error frames, frames of the wrong length and unknown identifiers are skipped; they neither count
// as status nor disturb the loop.
TEST(ExoControllerBus, BadFramesAreIgnored) {
  Rig rig;
  for (int i = 0; i < 10; ++i) rig.Tick();
  const uint32_t received = rig.tel().frames_received;
  for (int i = 0; i < 10; ++i) {
    rig.bus.ScriptErrorFrame(rig.t());
    CanFrame short_status = msg::Encode(msg::JointStatus{msg::Joint::kKnee, 1.0, 0, 0, 0});
    short_status.dlc = 7;
    rig.bus.Script(rig.t(), short_status);
    CanFrame unknown;
    unknown.id = 0x7ff;
    unknown.dlc = 8;
    rig.bus.Script(rig.t(), unknown);
    rig.Tick();
  }
  EXPECT_EQ(rig.bus.pending(), 0u);
  EXPECT_EQ(rig.tel().frames_received, received + 20);
  EXPECT_EQ(rig.ctl->state(), SafetyState::kRunning);
  EXPECT_EQ(rig.tel().est[1].q, Quantized(-0.47));
}

TEST(ExoControllerBus, FailedSendsAreCounted) {
  Rig rig;
  rig.Tick();  // tick 0: two commands and a heartbeat
  rig.bus.FailSends(CanStatus::kQueueFull);
  for (int i = 0; i < 10; ++i) rig.Tick();  // ticks 1..10: 20 commands, one heartbeat (tick 10)
  EXPECT_EQ(rig.tel().frames_sent, 3u);
  EXPECT_EQ(rig.tel().send_failures, 21u);
  EXPECT_TRUE(rig.bus.sent().empty());
}

}  // namespace
}  // namespace exotwin::controller
