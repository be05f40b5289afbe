#include "dsp/butterworth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

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


// FiltFilt as a padded copy filtered forward then backward (scipy's sosfiltfilt layout): the
// reference the in-place and batched versions must match bit for bit.
std::vector<double> PaddedFiltFilt(const std::vector<Biquad>& sos, const std::vector<double>& x) {
  const size_t n = x.size();
  size_t pad = 3 * (2 * sos.size() + 1);
  if (pad >= n) pad = n - 1;
  std::vector<double> ext;
  for (size_t i = pad; i >= 1; --i) ext.push_back(2.0 * x[0] - x[i]);
  ext.insert(ext.end(), x.begin(), x.end());
  for (size_t i = 1; i <= pad; ++i) ext.push_back(2.0 * x[n - 1] - x[n - 1 - i]);
  SosFilter f(sos);
  f.ResetSteady(ext.front());
  for (double& v : ext) v = f.Step(v);
  f.ResetSteady(ext.back());
  for (auto it = ext.rbegin(); it != ext.rend(); ++it) *it = f.Step(*it);
  return std::vector<double>(ext.begin() + pad, ext.begin() + pad + n);
}

TEST(FiltFilt, InPlaceAndBatchedEqualThePaddedCopyBitForBit) {
  const std::vector<Biquad> designs[] = {DesignButterworth(2, BandType::kLowPass, 1000.0, 7.0),
                                         DesignButterworth(4, BandType::kLowPass, 500.0, 30.0),
                                         DesignButterworth(2, BandType::kBandPass, 1000.0, 20.0, 80.0)};
  for (const auto& sos : designs)
    for (size_t n : {1, 2, 5, 9, 16, 1000}) {
      SCOPED_TRACE(std::to_string(sos.size()) + " sections, n " + std::to_string(n));
      std::vector<std::vector<double>> xs(11, std::vector<double>(n));
      for (size_t k = 0; k < xs.size(); ++k)
        for (size_t i = 0; i < n; ++i) xs[k][i] = std::sin(0.01 * (k + 1) * i) + 0.1 * std::cos(1.7 * i * i + k);
      std::vector<std::vector<double>> ref, batched = xs;
      for (const auto& x : xs) ref.push_back(PaddedFiltFilt(sos, x));
      std::vector<double>* ptr[11];
      for (size_t k = 0; k < 11; ++k) ptr[k] = &batched[k];
      FiltFiltInPlace(sos, ptr, 11);  // a block of eight (four pairs), then three (a pair and one)
      for (size_t k = 0; k < xs.size(); ++k) {
        EXPECT_EQ(FiltFilt(sos, xs[k]), ref[k]);
        std::vector<double> one = xs[k];
        FiltFiltInPlace(sos, one);
        EXPECT_EQ(one, ref[k]);
        EXPECT_EQ(batched[k], ref[k]);
      }
    }
  std::vector<double> a(10), b(11);
  std::vector<double>* ab[2] = {&a, &b};
  EXPECT_THROW(FiltFiltInPlace(designs[0], ab, 2), std::invalid_argument);
}

// Signals generated block by block and filtered forward as they come (FiltFiltGenerated) end as the
// padded copy's zero-phase filter, bit for bit: one to eight signals, records shorter than the pad,
// than one block (2048 samples) and a few blocks long; every sample generated, none outside [0, n).
TEST(FiltFilt, GeneratedBlockByBlockEqualsThePaddedCopyBitForBit) {
  const std::vector<Biquad> designs[] = {DesignButterworth(2, BandType::kLowPass, 1000.0, 7.0),
                                         DesignButterworth(4, BandType::kLowPass, 500.0, 30.0)};
  auto Value = [](size_t k, size_t i) { return std::sin(0.01 * (k + 1) * i) + 0.1 * std::cos(1.7 * i * i + k); };
  for (const auto& sos : designs)
    for (size_t n : {1, 2, 9, 2047, 2048, 2049, 5000})
      for (size_t count : {1, 3, 8}) {
        SCOPED_TRACE(std::to_string(sos.size()) + " sections, n " + std::to_string(n) + ", " + std::to_string(count) + " signals");
        std::vector<std::vector<double>> out(count, std::vector<double>(n, std::nan("")));
        std::vector<double>* ptr[8];
        for (size_t k = 0; k < count; ++k) ptr[k] = &out[k];
        std::vector<int> generated(n, 0);
        bool outside = false;
        FiltFiltGenerated(sos, ptr, count, [&](size_t begin, size_t end) {
          outside = outside || begin >= end || end > n;
          for (size_t i = begin; i < end && i < n; ++i) {
            ++generated[i];
            for (size_t k = 0; k < count; ++k) out[k][i] = Value(k, i);
          }
        });
        EXPECT_FALSE(outside);
        EXPECT_TRUE(std::all_of(generated.begin(), generated.end(), [](int g) { return g >= 1; }));
        for (size_t k = 0; k < count; ++k) {
          std::vector<double> x(n);
          for (size_t i = 0; i < n; ++i) x[i] = Value(k, i);
          EXPECT_EQ(out[k], PaddedFiltFilt(sos, x));
        }
      }
  std::vector<std::vector<double>> nine(9, std::vector<double>(10));
  std::vector<double>* ptr[9];
  for (size_t k = 0; k < 9; ++k) ptr[k] = &nine[k];
  EXPECT_THROW(FiltFiltGenerated(designs[0], ptr, 9, [](size_t, size_t) {}), std::invalid_argument);
  std::vector<double> a(10), b(11);
  std::vector<double>* ab[2] = {&a, &b};
  EXPECT_THROW(FiltFiltGenerated(designs[0], ab, 2, [](size_t, size_t) {}), std::invalid_argument);
}

// The low-pass of zeros is +0 everywhere (a column that is zero needs no filtering).
TEST(FiltFilt, ZerosStayPositiveZeros) {
  for (double fc : {1.5, 20.0, 50.0}) {
    const std::vector<double> y = FiltFilt(DesignButterworth(2, BandType::kLowPass, 500.0, fc), std::vector<double>(300, 0.0));
    for (double v : y) EXPECT_TRUE(v == 0.0 && !std::signbit(v));
  }
}

}  // namespace
}  // namespace exotwin::dsp
