// Tests of controller/hal_loop.h through its bus only (tests/controller/fake_can_bus.h): the HAL-3
// knee unit and the EMG amplifier are scripted HalKneeStatus and EmgSamples frames; the loop's
// promises are read back from the HalKneeCommand frames it sends:
//  - no status yet: enable = false, 0 N m; one command per tick, counter +1 per tick;
//  - for a held knee (thd = thdd = 0) the torque is the law of the mode: kNone 0 N m (enabled),
//    kImpedance tau_c = (mgl - mgl_v) sin th (Lee & Sankai, virtual_impedance.h), kAssist
//    tau = alpha_mu mu^ + tau_c with mu^ of HKS05 eq. 2-3 from the RMS envelopes (HKS05 eq. 1);
//    clamped at +-tau_max;
//  - a status older than status_timeout: enable = false, 0 N m on that tick; back when it returns;
//  - EMG counter gaps are counted; error frames and wrong-length frames are skipped.
// Ticks run at 1024 Hz so that tick times and ages are exact binary fractions.
#include "controller/hal_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "protocol/messages.h"
#include "tests/controller/fake_can_bus.h"

namespace exotwin::controller {
namespace {

using testing::FakeCanBus;
constexpr double kRate = 1024.0;     // Hz
constexpr double kDt = 1.0 / kRate;  // s, exact

struct Rig {
  FakeCanBus bus;
  HalLoopConfig cfg;
  std::unique_ptr<HalLoop> loop;
  double th = 0.4;            // rad, potentiometer angle (HAL convention: 0 hanging, + extension)
  double emg[msg::kEmgChannels] = {0, 0, 0, 0, 0};  // V after the amplifier
  uint8_t status_counter = 0, emg_counter = 0;
  int k = 0;

  explicit Rig(HalMode mode) {
    cfg.mode = mode;
    cfg.rate_hz = kRate;
    cfg.emg_fs = kRate;
    cfg.velocity.sample_rate_hz = kRate;
    cfg.status_timeout = 20 * kDt;
    cfg.impedance.actual = {0.12, 0.8, 6.0, 0.3};
    cfg.impedance.target = {0.0, 1.56, 2.0, 0.0};
    Build();
  }
  void Build() { loop = std::make_unique<HalLoop>(cfg, &bus); }
  double t() const { return k * kDt; }
  // One tick: the knee status (if `status`) and an EMG sample (if `emg_sample`) arrive first.
  msg::HalKneeCommand Tick(bool status = true, bool emg_sample = true) {
    if (status) {
      msg::HalKneeStatus s;
      s.angle = th;
      s.torque = 1.0;
      s.counter = status_counter++;
      bus.ScriptMessage(t(), s);
    }
    if (emg_sample) {
      msg::EmgSamples e;
      for (int c = 0; c < msg::kEmgChannels; ++c) e.volts[c] = emg[c];
      e.counter = emg_counter;
      emg_counter = (emg_counter + 1) & 0x0f;
      bus.ScriptMessage(t(), e);
    }
    bus.ClearSent();
    bus.AdvanceTo(t());
    loop->Tick(t());
    ++k;
    const std::vector<msg::HalKneeCommand> cmd = bus.SentMessages<msg::HalKneeCommand>();
    EXPECT_EQ(cmd.size(), 1u) << "one command per tick";
    EXPECT_EQ(bus.sent().size(), 1u);
    return cmd.empty() ? msg::HalKneeCommand{} : cmd.back();
  }
  const HalTelemetry& tel() const { return loop->telemetry(); }
};

double QuantizedAngle(double th) {
  msg::HalKneeStatus s, d;
  s.angle = th;
  EXPECT_TRUE(msg::Decode(msg::Encode(s), &d));
  return d.angle;
}
double QuantizedEmg(double v) {
  msg::EmgSamples s, d;
  s.volts[0] = v;
  EXPECT_TRUE(msg::Decode(msg::Encode(s), &d));
  return d.volts[0];
}
constexpr double kLsb = msg::kCommandTorqueScale;

TEST(HalLoopBus, DisabledUntilTheKneeReports) {
  Rig rig(HalMode::kImpedance);
  for (int i = 0; i < 5; ++i) {
    const msg::HalKneeCommand c = rig.Tick(false, true);
    EXPECT_FALSE(c.enable);
    EXPECT_EQ(c.torque, 0.0);
    EXPECT_EQ(c.counter, static_cast<uint8_t>(i));
  }
  const msg::HalKneeCommand c = rig.Tick();
  EXPECT_TRUE(c.enable);
  EXPECT_NE(c.torque, 0.0);
  EXPECT_EQ(c.counter, 5);
}

TEST(HalLoopBus, NoneModeEnabledWithZeroTorque) {
  Rig rig(HalMode::kNone);
  for (int i = 0; i < 10; ++i) {
    const msg::HalKneeCommand c = rig.Tick();
    EXPECT_TRUE(c.enable);
    EXPECT_EQ(c.torque, 0.0);
  }
}

// Held knee: thd = thdd = 0 exactly (the estimator starts at rest), so tau_c reduces to the gravity
// term; the Coulomb term is (C - C_v) tanh(0) = 0.
TEST(HalLoopBus, ImpedanceModeHeldKneeTorqueIsTheGravityCompensation) {
  Rig rig(HalMode::kImpedance);
  const double th = QuantizedAngle(rig.th);
  const double expected = (rig.cfg.impedance.actual.mgl - rig.cfg.impedance.target.mgl) * std::sin(th);
  for (int i = 0; i < 30; ++i) {
    const msg::HalKneeCommand c = rig.Tick();
    EXPECT_EQ(rig.tel().thd, 0.0);
    EXPECT_DOUBLE_EQ(rig.tel().tau_cmd, expected) << "tick " << i;
    EXPECT_NEAR(c.torque, expected, kLsb / 2 + 1e-12);
    EXPECT_TRUE(c.enable);
  }
}

TEST(HalLoopBus, CommandClampedAtTauMax) {
  for (double th : {1.2, -1.2}) {  // |(mgl - mgl_v) sin th| = 3.7 N m
    Rig rig(HalMode::kImpedance);
    rig.cfg.tau_max = 1.0;
    rig.Build();
    rig.th = th;
    EXPECT_DOUBLE_EQ(rig.Tick().torque, std::copysign(1.0, th));
    EXPECT_DOUBLE_EQ(rig.tel().tau_cmd, std::copysign(1.0, th));
  }
}

// HKS05 eq. 6 with alpha_zeta = 0: tau = alpha_mu [(a_e E_e + b_e) - (a_f E_f + b_f)] + tau_c, where the
// RMS envelope of a constant EMG level is that level once the window (HKS05 eq. 1) is full.
TEST(HalLoopBus, AssistModeTorqueIsTheEmgLawPlusCompensation) {
  Rig rig(HalMode::kAssist);
  rig.cfg.assist.dt = kDt;
  rig.cfg.assist.rls.dt = kDt;
  rig.cfg.assist.alpha_mu = 0.8;
  rig.cfg.assist.alpha_zeta = 0.0;
  rig.cfg.assist.emg.extensor = {40.0, -1.0};
  rig.cfg.assist.emg.flexor = {25.0, -0.5};
  rig.Build();
  rig.emg[rig.cfg.extensor_channel] = 0.3;
  rig.emg[rig.cfg.flexor_channel] = -0.12;  // the envelope is an RMS: the sign does not matter
  const double E_e = QuantizedEmg(0.3), E_f = std::abs(QuantizedEmg(-0.12));
  const double tau_c = (rig.cfg.impedance.actual.mgl - rig.cfg.impedance.target.mgl) *
                       std::sin(QuantizedAngle(rig.th));
  const double mu = (40.0 * E_e - 1.0) - (25.0 * E_f - 0.5);
  const double expected = 0.8 * mu + tau_c;
  ASSERT_LT(std::abs(expected), rig.cfg.tau_max);
  msg::HalKneeCommand c;
  for (int i = 0; i < 200; ++i) c = rig.Tick();  // > 0.1 s: the RMS window is full
  EXPECT_NEAR(rig.tel().E_e, E_e, 1e-12);
  EXPECT_NEAR(rig.tel().E_f, E_f, 1e-12);
  EXPECT_NEAR(rig.tel().assist.tau_mu, 0.8 * mu, 1e-9);
  EXPECT_EQ(rig.tel().assist.tau_zeta, 0.0);
  EXPECT_NEAR(rig.tel().tau_cmd, expected, 1e-9);
  EXPECT_NEAR(c.torque, expected, kLsb / 2 + 1e-9);
  EXPECT_TRUE(c.enable);
}

// status_timeout = 20 ticks: a status 20 ticks old still drives the knee; 21 ticks: torque off on
// that tick; the next status re-enables (HalLoop latches nothing).
TEST(HalLoopBus, SilentKneeTorqueOffAfterStatusTimeout) {
  Rig rig(HalMode::kImpedance);
  for (int i = 0; i < 10; ++i) rig.Tick();
  for (int i = 1; i <= 20; ++i) {
    const msg::HalKneeCommand c = rig.Tick(false, true);
    EXPECT_TRUE(c.enable) << i << " ticks after the last status";
    EXPECT_NE(c.torque, 0.0);
  }
  msg::HalKneeCommand c = rig.Tick(false, true);
  EXPECT_FALSE(c.enable);
  EXPECT_EQ(c.torque, 0.0);
  EXPECT_FALSE(rig.tel().enabled);
  c = rig.Tick();
  EXPECT_TRUE(c.enable);
  EXPECT_NE(c.torque, 0.0);
}

TEST(HalLoopBus, EmgCounterGapsAreCounted) {
  Rig rig(HalMode::kNone);
  for (int i = 0; i < 40; ++i) rig.Tick();  // wraps 15 -> 0 twice: no gap
  EXPECT_EQ(rig.tel().emg_gaps, 0u);
  rig.emg_counter = (rig.emg_counter + 2) & 0x0f;  // one sample lost
  rig.Tick();
  rig.Tick(true, false);  // no sample this tick, the next one continues the sequence: no gap
  rig.Tick();
  EXPECT_EQ(rig.tel().emg_gaps, 1u);
  EXPECT_EQ(rig.tel().emg_frames, 42u);
}

TEST(HalLoopBus, BadFramesAreIgnored) {
  Rig rig(HalMode::kImpedance);
  for (int i = 0; i < 5; ++i) rig.Tick();
  const double tau = rig.tel().tau_cmd;
  for (int i = 0; i < 5; ++i) {
    rig.bus.ScriptErrorFrame(rig.t());
    CanFrame short_status = msg::Encode(msg::HalKneeStatus{-1.0, 0, 0, 0});
    short_status.dlc = 5;
    rig.bus.Script(rig.t(), short_status);
    rig.Tick();
  }
  EXPECT_EQ(rig.tel().status_frames, 10u);
  EXPECT_DOUBLE_EQ(rig.tel().tau_cmd, tau);
}

TEST(HalLoopBus, FailedSendsAreCounted) {
  Rig rig(HalMode::kNone);
  rig.bus.FailSends(CanStatus::kBusOff);
  for (int i = 0; i < 3; ++i) {
    rig.bus.AdvanceTo(i * kDt);
    rig.loop->Tick(i * kDt);
  }
  EXPECT_EQ(rig.tel().send_failures, 3u);
  EXPECT_TRUE(rig.bus.sent().empty());
}

}  // namespace
}  // namespace exotwin::controller
