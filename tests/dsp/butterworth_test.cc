#include "dsp/butterworth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace exotwin::dsp {
namespace {

// scipy.signal.butter(2, 20, fs=1000): b = [0.00362168, 0.00724336, 0.00362168],
// a = [1, -1.82269493, 0.83718165] (the paper's derivative filter).
TEST(Butterworth, SecondOrderLowPassMatchesReferenceCoefficients) {
  const auto sos = DesignButterworth(2, BandType::kLowPass, 1000.0, 20.0);
  ASSERT_EQ(sos.size(), 1u);
  EXPECT_NEAR(sos[0].a1, -1.82269493, 1e-7);
  EXPECT_NEAR(sos[0].a2, 0.83718165, 1e-7);
  EXPECT_NEAR(sos[0].b0, 0.00362168, 1e-7);
  EXPECT_NEAR(sos[0].b1, 0.00724336, 1e-7);
  EXPECT_NEAR(sos[0].b2, 0.00362168, 1e-7);
}

// Defining property of Butterworth: |H| = 1/sqrt(2) at the (pre-warped) cut-offs, flat pass band.
TEST(Butterworth, MagnitudeAtCutOffs) {
  const double r = 1.0 / std::sqrt(2.0);
  for (int order : {1, 2, 3, 4, 5}) {
    const auto lp = DesignButterworth(order, BandType::kLowPass, 1000.0, 2.0);
    EXPECT_NEAR(MagnitudeResponse(lp, 1000.0, 2.0), r, 1e-9);
    EXPECT_NEAR(MagnitudeResponse(lp, 1000.0, 0.001), 1.0, 1e-6);
    const auto hp = DesignButterworth(order, BandType::kHighPass, 1000.0, 20.0);
    EXPECT_NEAR(MagnitudeResponse(hp, 1000.0, 20.0), r, 1e-9);
    EXPECT_NEAR(MagnitudeResponse(hp, 1000.0, 499.9), 1.0, 1e-6);
  }
  // The EMG amplifier's 4th-order band-pass 20-450 Hz at 1 kHz (8 poles).
  const auto bp = DesignButterworth(4, BandType::kBandPass, 1000.0, 20.0, 450.0);
  EXPECT_EQ(bp.size(), 4u);
  EXPECT_NEAR(MagnitudeResponse(bp, 1000.0, 20.0), r, 1e-9);
  EXPECT_NEAR(MagnitudeResponse(bp, 1000.0, 450.0), r, 1e-9);
  EXPECT_NEAR(MagnitudeResponse(bp, 1000.0, 95.0), 1.0, 1e-3);
  EXPECT_LT(MagnitudeResponse(bp, 1000.0, 2.0), 1e-3);
}

TEST(Butterworth, CausalFilterFollowsDcAndAttenuatesStopBand) {
  SosFilter f(DesignButterworth(4, BandType::kLowPass, 1000.0, 2.0));
  f.ResetSteady(3.0);
  for (int i = 0; i < 100; ++i) EXPECT_NEAR(f.Step(3.0), 3.0, 1e-9);  // steady start: no transient
  f.Reset();
  double peak = 0;
  for (int i = 0; i < 5000; ++i) {
    const double y = f.Step(std::sin(2 * M_PI * 50.0 * i / 1000.0));
    if (i > 3000) peak = std::max(peak, std::abs(y));
  }
  EXPECT_NEAR(peak, MagnitudeResponse(DesignButterworth(4, BandType::kLowPass, 1000.0, 2.0), 1000.0, 50.0),
              1e-6);
}

// Zero-phase: a 2 Hz sine through the 20 Hz filter forward-backward keeps its phase and has gain
// |H(2 Hz)|^2 (both passes).
TEST(Butterworth, FiltFiltIsZeroPhase) {
  const auto sos = DesignButterworth(2, BandType::kLowPass, 1000.0, 20.0);
  std::vector<double> x(4000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = std::sin(2 * M_PI * 2.0 * i / 1000.0 + 0.3);
  const auto y = FiltFilt(sos, x);
  const double g = std::pow(MagnitudeResponse(sos, 1000.0, 2.0), 2);
  for (size_t i = 500; i < 3500; ++i) EXPECT_NEAR(y[i], g * x[i], 1e-6);
}

TEST(Butterworth, RejectsBadDesigns) {
  EXPECT_THROW(DesignButterworth(0, BandType::kLowPass, 1000, 20), std::invalid_argument);
  EXPECT_THROW(DesignButterworth(2, BandType::kLowPass, 1000, 600), std::invalid_argument);
  EXPECT_THROW(DesignButterworth(2, BandType::kBandPass, 1000, 450, 20), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin::dsp
