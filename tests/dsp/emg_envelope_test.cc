// Tests of dsp/emg_envelope.h with signals whose answer is known in closed form: a sinusoid of
// constant amplitude A has the rectified mean (2/pi) A, AM carriers follow (2/pi) A(t), the
// Butterworth designs have gain 1/sqrt(2) at their cut-offs, and the RMS of a sine is A/sqrt(2).
#include "dsp/emg_envelope.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gauss.h"

namespace exotwin::dsp {
namespace {

constexpr double kFs = 1000.0;

using exotwin::testing::Gauss;

double Amp(double t) { return 1.0 + 0.5 * std::sin(2 * M_PI * 0.5 * t); }  // modulation, V

std::vector<double> Sine(double amplitude, double f, size_t n) {
  std::vector<double> x(n);
  for (size_t k = 0; k < n; ++k) x[k] = amplitude * std::sin(2 * M_PI * f * k / kFs);
  return x;
}

TEST(EmgEnvelope, DesignsHaveButterworthGainAtTheirCutoffs) {
  const double r = 1 / std::sqrt(2.0);
  const auto bp = EmgBandPassDesign(kFs);
  EXPECT_EQ(bp.size(), 2u);  // 4 poles: the paper's 4th-order band-pass
  EXPECT_NEAR(MagnitudeResponse(bp, kFs, 20.0), r, 1e-9);
  EXPECT_NEAR(MagnitudeResponse(bp, kFs, 450.0), r, 1e-9);
  const auto lp = EnvelopeLowPassDesign(kFs, 2.0);
  EXPECT_EQ(lp.size(), 2u);  // 4th order
  EXPECT_NEAR(MagnitudeResponse(lp, kFs, 2.0), r, 1e-9);
  EXPECT_NEAR(MagnitudeResponse(lp, kFs, 4.0), 1 / std::sqrt(1 + std::pow(2.0, 8)), 1e-3);  // |H| at 2 fc
}

TEST(EmgEnvelope, BandPassPassesTheEmgBandAndStopsMotionArtefacts) {
  auto gain = [](double f) {
    EmgBandPass bp(kFs);
    double peak = 0;
    for (int k = 0; k < 20000; ++k) {
      const double y = bp.Step(std::sin(2 * M_PI * f * k / kFs));
      if (k > 15000) peak = std::max(peak, std::abs(y));
    }
    return peak;
  };
  EXPECT_NEAR(gain(100), 1.0, 0.02);
  EXPECT_NEAR(gain(20), 1 / std::sqrt(2.0), 0.03);  // -3 dB corner
  EXPECT_LT(gain(3), 0.03);  // motion artefact band: (3/20)^2 = 0.0225 for the 2-pole high side
}

TEST(EmgEnvelope, RectifyIsTheAbsoluteValue) {
  EXPECT_EQ(Rectify(-0.25), 0.25);
  EXPECT_EQ(Rectify(0.5), 0.5);
  EXPECT_EQ(Rectify(0.0), 0.0);
}

// Constant amplitude A = 0.8 V at 97 Hz: every variant settles at the rectified mean (2/pi) A.
TEST(EmgEnvelope, EnvelopeOfAConstantAmplitudeSinusoidIsTwoOverPiTimesTheAmplitude) {
  const double A = 0.8, expected = 2 / M_PI * A;
  const std::vector<double> x = Sine(A, 97.0, 12000);
  const std::vector<double> zero_phase = LinearEnvelopeZeroPhase(x, kFs);
  const std::vector<double> causal = LinearEnvelopeCausal(x, kFs);
  const std::vector<double> padded = ZeroPhaseEnvelope(
      DesignButterworth(2, BandType::kHighPass, kFs, 20.0), EnvelopeLowPassDesign(kFs, 2.0), x, 1000);
  ASSERT_EQ(zero_phase.size(), x.size());
  ASSERT_EQ(causal.size(), x.size());
  ASSERT_EQ(padded.size(), x.size());
  for (size_t k = 3000; k < 9000; ++k) {
    EXPECT_NEAR(zero_phase[k], expected, 0.005 * expected);
    EXPECT_NEAR(padded[k], expected, 0.005 * expected);
  }
  for (size_t k = 4000; k < x.size(); ++k) EXPECT_NEAR(causal[k], expected, 0.005 * expected);
}

TEST(EmgEnvelope, LinearEnvelopeOfAKnownAmSignal) {
  // x = A(t) sin(2 pi 97 t): |x| has mean (2/pi) A(t); the 2 Hz envelope must return it.
  std::vector<double> x;
  for (int k = 0; k < 20000; ++k) {
    const double t = k / kFs;
    x.push_back(Amp(t) * std::sin(2 * M_PI * 97 * t));
  }
  const std::vector<double> off = LinearEnvelopeZeroPhase(x, kFs);
  double max_err = 0;
  for (size_t k = 2000; k < 18000; ++k)
    max_err = std::max(max_err, std::abs(off[k] - 2 / M_PI * Amp(k / kFs)));
  EXPECT_LT(max_err, 0.02 * 2 / M_PI * 1.5);  // < 2 % of the peak envelope, zero phase
  // Causal: same amplitude, lagged by the filter's group delay (~0.26 s at DC for 4th order at
  // 2 Hz, ~0.21 s at 0.5 Hz). Find the lag that best aligns it.
  LinearEnvelope le(kFs);
  std::vector<double> on;
  for (double v : x) on.push_back(le.Step(v));
  int best_lag = 0;
  double best = 1e9;
  for (int lag = 0; lag < 500; lag += 5) {
    double e = 0;
    for (size_t k = 5000; k < 19000; ++k) e += std::pow(on[k] - 2 / M_PI * Amp((k - lag) / kFs), 2);
    if (e < best) best = e, best_lag = lag;
  }
  std::printf("[emg] causal 2 Hz envelope lag at 0.5 Hz modulation: %d ms\n", best_lag);
  EXPECT_GT(best_lag, 150);
  EXPECT_LT(best_lag, 350);
  EXPECT_LT(std::sqrt(best / 14000), 0.03);
}

// With no padding the zero-phase envelope is FiltFilt(prefilter), |.|, FiltFilt(lowpass) exactly.
TEST(EmgEnvelope, ZeroPhaseEnvelopeIsTheComposedFilters) {
  Gauss g;
  std::vector<double> x(3000);
  for (double& v : x) v = 0.1 * g();
  const auto bp = EmgBandPassDesign(kFs), lp = EnvelopeLowPassDesign(kFs, 2.0);
  std::vector<double> ref = FiltFilt(bp, x);
  for (double& v : ref) v = std::abs(v);
  ref = FiltFilt(lp, ref);
  EXPECT_EQ(ZeroPhaseEnvelope(bp, lp, x), ref);
  EXPECT_EQ(LinearEnvelopeZeroPhase(x, kFs), ref);
  EXPECT_TRUE(ZeroPhaseEnvelope(bp, lp, {}, 10).empty());
}

// With padding: each FiltFilt on the odd-reflected extension, cropped (written out here); several
// signals at once (ZeroPhaseEnvelopes) give each one's envelope bit for bit, a pad beyond the record
// clipped to n - 1.
TEST(EmgEnvelope, PaddedEnvelopesOfSeveralSignalsAreEachOnesBitForBit) {
  Gauss g;
  const auto hp = DesignButterworth(2, BandType::kHighPass, kFs, 20.0), lp = EnvelopeLowPassDesign(kFs, 2.0);
  auto padded_filtfilt = [](const std::vector<Biquad>& sos, const std::vector<double>& x, size_t pad) {
    const size_t n = x.size();
    std::vector<double> y;
    for (size_t k = pad; k >= 1; --k) y.push_back(2 * x[0] - x[k]);
    y.insert(y.end(), x.begin(), x.end());
    for (size_t k = 1; k <= pad; ++k) y.push_back(2 * x[n - 1] - x[n - 1 - k]);
    y = FiltFilt(sos, y);
    return std::vector<double>(y.begin() + static_cast<long>(pad), y.begin() + static_cast<long>(pad + n));
  };
  for (size_t n : {5, 800, 3000})
    for (size_t pad : {size_t{0}, size_t{4}, size_t{1000}}) {
      SCOPED_TRACE("n " + std::to_string(n) + ", pad " + std::to_string(pad));
      std::vector<std::vector<double>> xs(3, std::vector<double>(n));
      for (auto& x : xs)
        for (double& v : x) v = 0.1 * g();
      std::vector<const std::vector<double>*> ptr = {&xs[0], &xs[1], &xs[2]};
      const std::vector<std::vector<double>> together = ZeroPhaseEnvelopes(hp, lp, ptr, pad);
      ASSERT_EQ(together.size(), 3u);
      for (size_t k = 0; k < 3; ++k) {
        const size_t p = std::min(pad, n - 1);
        std::vector<double> ref = p > 0 ? padded_filtfilt(hp, xs[k], p) : FiltFilt(hp, xs[k]);
        for (double& v : ref) v = std::abs(v);
        ref = p > 0 ? padded_filtfilt(lp, ref, p) : FiltFilt(lp, ref);
        EXPECT_EQ(ZeroPhaseEnvelope(hp, lp, xs[k], pad), ref);
        EXPECT_EQ(together[k], ref);
      }
    }
  const std::vector<double> a(10), b(11);
  EXPECT_THROW(ZeroPhaseEnvelopes(hp, lp, {&a, &b}, 3), std::invalid_argument);
}

TEST(EmgEnvelope, RmsEnvelopeIsEq1) {
  RmsEnvelope rms(kFs, 0.1);
  EXPECT_EQ(rms.window(), 100u);
  double y = 0;
  for (int k = 0; k < 5000; ++k) y = rms.Step(0.3 * std::sin(2 * M_PI * 50 * k / kFs));
  EXPECT_NEAR(y, 0.3 / std::sqrt(2.0), 1e-9);  // 5 periods in the window: exact
  // Against a brute-force HKS05 eq. 1 on a random signal.
  Gauss g;
  RmsEnvelope r2(kFs, 0.05);
  std::vector<double> x;
  for (int k = 0; k < 3000; ++k) {
    x.push_back(g());
    const double e = r2.Step(x.back());
    if (k >= 49) {
      double s = 0;
      for (int i = k - 49; i <= k; ++i) s += x[i] * x[i];
      ASSERT_NEAR(e, std::sqrt(s / 50), 1e-12);
    }
  }
  EXPECT_THROW(RmsEnvelope(kFs, 1e-4), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin::dsp
