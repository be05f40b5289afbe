// Tests of controller/emg_processing.h with signals whose answer is known in closed form:
// AM carriers (envelope = 2/pi x amplitude for a rectified sine), RMS of a sine (A/sqrt 2), and the
// false-activation rate of the eq. (13) threshold on relaxed Gaussian noise (half-normal theory).
#include "controller/emg_processing.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace exotwin {
namespace {

constexpr double kFs = 1000.0;

// Gaussian deviates from raw mt19937_64 bits (Box-Muller), reproducible.
struct Gauss {
  std::mt19937_64 e{12345};
  double U() { return (static_cast<double>(e() >> 11) + 0.5) * 0x1.0p-53; }
  double operator()() { return std::sqrt(-2 * std::log(U())) * std::cos(2 * M_PI * U()); }
};

double Amp(double t) { return 1.0 + 0.5 * std::sin(2 * M_PI * 0.5 * t); }  // modulation, V

TEST(EmgProcessing, BandPassPassesTheEmgBandAndStopsMotionArtefacts) {
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

TEST(EmgProcessing, LinearEnvelopeOfAKnownAmSignal) {
  // x = A(t) sin(2 pi 97 t): |x| has mean (2/pi) A(t); the 2 Hz envelope must return it.
  std::vector<double> x;
  for (int k = 0; k < 20000; ++k) {
    const double t = k / kFs;
    x.push_back(Amp(t) * std::sin(2 * M_PI * 97 * t));
  }
  const std::vector<double> off = LinearEnvelopeOffline(x, kFs);
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

TEST(EmgProcessing, RmsEnvelopeIsEq1) {
  RmsEnvelope rms(kFs, 0.1);
  EXPECT_EQ(rms.window(), 100u);
  double y = 0;
  for (int k = 0; k < 5000; ++k) y = rms.Step(0.3 * std::sin(2 * M_PI * 50 * k / kFs));
  EXPECT_NEAR(y, 0.3 / std::sqrt(2.0), 1e-9);  // 5 periods in the window: exact
  // Against a brute-force eq. (1) on a random signal.
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
}

TEST(EmgProcessing, MvcPeaksAndNormalization) {
  std::vector<double> env(12000, 0.01);
  const double levels[] = {0.50, 0.60, 0.55, 0.20};
  for (int trial = 0; trial < 4; ++trial)
    for (int k = 0; k < 1000; ++k)
      env[1000 + trial * 2500 + k] = levels[trial] * std::sin(M_PI * k / 1000.0);
  EXPECT_NEAR(MvcFromPeaks(env, kFs, 3), (0.5 + 0.6 + 0.55) / 3, 1e-4);
  const std::vector<double> le = NormalizeToMvc(env, 0.55);
  EXPECT_NEAR(le[1000 + 2500 + 500], 0.6 / 0.55, 1e-9);
  EXPECT_THROW(MvcFromPeaks(env, kFs, 5), std::invalid_argument);
}

TEST(EmgProcessing, ThresholdFalseActivationRateOnRelaxedNoise) {
  // Relaxed EMG: Gaussian noise (0.1 V RMS after the amplifier), band-passed 20-450 Hz.
  Gauss g;
  EmgBandPass bp(kFs);
  std::vector<double> chi, chi_test;
  for (int k = 0; k < 2000000; ++k) {
    const double v = Rectify(bp.Step(0.1 * g()));
    (k < 1000000 ? chi : chi_test).push_back(v);
  }
  const ActivationThreshold th = FitActivationThreshold(chi);
  // chi = |x| of a Gaussian x is half-normal: mean sigma sqrt(2/pi), SD sigma sqrt(1 - 2/pi), so
  // Z = 2.606 sigma and P(chi > Z) = 2 (1 - Phi(2.606)) = 0.92 %: eq. (13) applied sample by sample to
  // the rectified signal flags ~0.9 % of relaxed samples, not the 0.13 % of a Gaussian 3 SD.
  const double rate = ActiveFraction(th, chi_test);
  std::printf("[emg] eq. 13 false-activation rate on rectified relaxed noise: %.3f %%\n", 100 * rate);
  EXPECT_NEAR(rate, 0.0092, 0.0008);
  // On the linear envelope (a smoothed, nearly Gaussian variable) the 3 SD rule gives the Gaussian
  // tail of ~0.13 % (slightly more: the envelope is a little right-skewed).
  LinearEnvelope le(kFs);
  std::vector<double> env, env_test;
  for (size_t k = 0; k < chi.size(); ++k) env.push_back(le.Step(chi[k]));
  for (size_t k = 0; k < chi_test.size(); ++k) env_test.push_back(le.Step(chi_test[k]));
  env.erase(env.begin(), env.begin() + 5000);  // start-up transient
  const double rate_env = ActiveFraction(FitActivationThreshold(env), env_test);
  std::printf("[emg] eq. 13 false-activation rate on the linear envelope: %.3f %%\n", 100 * rate_env);
  EXPECT_GT(rate_env, 0.0003);
  EXPECT_LT(rate_env, 0.005);
}

}  // namespace
}  // namespace exotwin
