#include "hwsim/sensors.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hwsim/emg_amplifier.h"

namespace exotwin::hwsim {
namespace {

// Repeatability 0.02 % FS of 120 N m = 0.024 N m (1 sigma); resolution 0.015 N m; mean error at a
// constant torque = the non-linear bow (<= 0.03 % FS = 0.036 N m).
TEST(TorqueSensor, NoiseResolutionAndNonlinearityMatchSpec) {
  TorqueSensor s(TorqueSensorSpec{}, 1);
  const double tau = 40.0;
  double sum = 0, sum2 = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double r = s.Read(tau);
    EXPECT_NEAR(std::remainder(r, 0.015), 0.0, 1e-9);  // on the LSB grid
    sum += r;
    sum2 += r * r;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(sd, 0.024, 0.002);  // quantization adds 0.015/sqrt(12) = 0.0043 in quadrature
  const double x = tau / 120.0;
  const double bow = 0.0003 * 120 * (x - x * x * x) / (2 / (3 * std::sqrt(3.0)));
  EXPECT_NEAR(mean - tau, bow, 0.002);
  EXPECT_LE(std::abs(bow), 0.036 + 1e-12);
}

TEST(TorqueSensor, SaturatesAndFaults) {
  TorqueSensor s(TorqueSensorSpec{}, 2);
  EXPECT_LE(s.Read(500.0), 120.0);
  EXPECT_GE(s.Read(-500.0), -120.0);
  const double before = s.Read(10.0);
  s.SetFault(SensorFault::kStuck);
  EXPECT_EQ(s.Read(50.0), before);
  s.SetFault(SensorFault::kNaN);
  EXPECT_TRUE(std::isnan(s.Read(50.0)));
}

TEST(Encoder, QuantizesToCounts) {
  Encoder e(EncoderSpec{});
  const double res = 2 * M_PI / 524288.0;
  EXPECT_DOUBLE_EQ(e.resolution(), res);
  const double r = e.Read(0.123456789);
  EXPECT_LE(std::abs(r - 0.123456789), res / 2 + 1e-15);
  EXPECT_NEAR(std::remainder(r, res), 0.0, 1e-12);
  e.SetFault(SensorFault::kGlitch);
  EXPECT_NEAR(e.Read(0.1), 0.3, res);
}

// First-order lag: after one time constant the applied torque reaches 1 - 1/e of a step command.
TEST(MotorDriver, LagSaturationWatchdog) {
  MotorDriver d(MotorDriverSpec{1e-3, 50.0, 0.01});
  d.Command(0.0, 10.0, true);
  double a = 0;
  for (int i = 1; i <= 10; ++i) a = d.Update(i * 1e-4, 1e-4);
  EXPECT_NEAR(a, 10.0 * (1 - std::exp(-1.0)), 1e-9);
  d.Command(0.001, 500.0, true);
  for (int i = 0; i < 100; ++i) a = d.Update(0.001 + i * 1e-4, 1e-4);
  EXPECT_NEAR(a, 50.0, 0.01);  // saturated (10 time constants: 44 e^-10 = 0.002 left)
  // No command for more than 10 ms: watchdog trips and the torque decays to zero.
  for (int i = 0; i < 300; ++i) a = d.Update(0.011 + i * 1e-4, 1e-4);
  EXPECT_TRUE(d.watchdog_tripped());
  EXPECT_NEAR(a, 0.0, 1e-6);
}

// Gain 1000 in the pass band, attenuation below 20 Hz, quantization to the ADC step.
TEST(EmgAmplifier, GainBandAndQuantization) {
  EmgAmplifier amp;
  double peak100 = 0, peak2 = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i / 1000.0;
    std::array<double, 5> in{};
    in[0] = 1e-3 * std::sin(2 * M_PI * 100 * t);  // 1 mV at 100 Hz -> 1 V
    in[1] = 1e-3 * std::sin(2 * M_PI * 2 * t);    // 1 mV at 2 Hz -> attenuated
    const auto out = amp.Sample(in);
    if (i > 2000) {
      peak100 = std::max(peak100, std::abs(out[0]));
      peak2 = std::max(peak2, std::abs(out[1]));
    }
    EXPECT_NEAR(std::remainder(out[0], amp.lsb()), 0.0, 1e-12);
  }
  EXPECT_NEAR(peak100, 1.0, 0.02);
  EXPECT_LT(peak2, 0.01);
}

}  // namespace
}  // namespace exotwin::hwsim
