// Tests of dsp/derivatives.h against closed forms: central differences are exact for quadratics, and
// the zero-phase derivatives of a sine are its analytic derivatives times the filter's two-pass gain.
#include "dsp/derivatives.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "dsp/butterworth.h"

namespace exotwin::dsp {
namespace {

TEST(Derivatives, GradientIsExactForQuadratics) {
  std::vector<double> x(50);
  for (size_t i = 0; i < x.size(); ++i) x[i] = 0.5 * std::pow(0.01 * i, 2) + 2 * 0.01 * i;
  const auto d = Gradient(x, 0.01);
  for (size_t i = 1; i + 1 < x.size(); ++i) EXPECT_NEAR(d[i], 0.01 * i + 2, 1e-9);
  // One-sided at the ends: the forward / backward difference.
  EXPECT_NEAR(d.front(), (x[1] - x[0]) / 0.01, 1e-12);
  EXPECT_NEAR(d.back(), (x[49] - x[48]) / 0.01, 1e-12);
  EXPECT_EQ(Gradient({3.0}, 0.01), std::vector<double>(1, 0.0));
}

// x = A sin(w t + p) at 1 kHz through the paper's 20 Hz filter: filtered = g x, first = c g A w cos(.),
// second = -c^2 g A w^2 sin(.), g = |H(f)|^2 (zero phase: no shift) and c = sin(w dt) / (w dt), the
// exact gain of a central difference on a sampled sinusoid.
TEST(Derivatives, ZeroPhaseDerivativesOfASine) {
  const double dt = 1e-3, f = 1.5, w = 2 * M_PI * f, A = 0.7, p = 0.4;
  std::vector<double> x(6000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = A * std::sin(w * i * dt + p);
  const Derivatives d = ZeroPhaseDerivatives(x, dt, 20.0);
  ASSERT_EQ(d.filtered.size(), x.size());
  ASSERT_EQ(d.first.size(), x.size());
  ASSERT_EQ(d.second.size(), x.size());
  const double g = std::pow(MagnitudeResponse(DesignButterworth(2, BandType::kLowPass, 1000.0, 20.0), 1000.0, f), 2);
  const double c = std::sin(w * dt) / (w * dt);
  for (size_t i = 500; i + 500 < x.size(); ++i) {
    const double t = i * dt;
    EXPECT_NEAR(d.filtered[i], g * A * std::sin(w * t + p), 1e-9);
    EXPECT_NEAR(d.first[i], c * g * A * w * std::cos(w * t + p), 1e-7);
    EXPECT_NEAR(d.second[i], -c * c * g * A * w * w * std::sin(w * t + p), 1e-5);
  }
}

// Noise above the cut-off is removed before differentiation: a 200 Hz ripple of 1e-3 rad would give
// an acceleration ripple of 1e-3 (2 pi 200)^2 ~ 1600 rad/s^2 without the filter.
TEST(Derivatives, ZeroPhaseDerivativesRejectRippleAboveTheCutoff) {
  const double dt = 1e-3;
  std::vector<double> x(4000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = 1e-3 * std::sin(2 * M_PI * 200.0 * i * dt);
  const Derivatives d = ZeroPhaseDerivatives(x, dt, 20.0);
  for (size_t i = 500; i + 500 < x.size(); ++i) EXPECT_LT(std::abs(d.second[i]), 1.0);
}

// ZeroPhaseRates writes ZeroPhaseDerivatives' first and second derivatives, bit for bit, into vectors
// whatever they held (longer, shorter); GradientInto gives Gradient.
TEST(Derivatives, ZeroPhaseRatesAreZeroPhaseDerivativesBitForBit) {
  std::vector<double> x(3001);
  for (size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.013 * i) + 0.3 * std::cos(0.11 * i) + 1e-3 * ((i * 7919) % 13);
  const double dt = 1e-3, fc = 12.0;
  const Derivatives d = ZeroPhaseDerivatives(x, dt, fc);
  std::vector<double> first(5000, 7.0), second(10, -1.0);
  ZeroPhaseRates(x, dt, fc, &first, &second);
  EXPECT_EQ(first, d.first);
  EXPECT_EQ(second, d.second);
  std::vector<double> g(3, 1.0);
  GradientInto(x, dt, &g);
  EXPECT_EQ(g, Gradient(x, dt));
}

TEST(Derivatives, RejectsACutoffAboveNyquist) {
  EXPECT_THROW(ZeroPhaseDerivatives(std::vector<double>(100, 0.0), 1e-3, 600.0), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin::dsp
