// Tests of sim/synthetic_emg.h against published surface-EMG properties:
// - relaxed levels after gain 1000: ~0.1 V extensor, ~0.04 V flexor (Hayashi et al., Exp. section);
// - median frequency of the power spectrum within 60-120 Hz, the range of quadriceps surface EMG
//   in isometric contractions (e.g. Pincivero et al. 2001, J Appl Physiol 90:804), and most power
//   within 20-450 Hz (De Luca 1997, the band of the Bagnoli amplifier used by Hwang & Jeon);
// - amplitude distribution close to Gaussian at a constant contraction (Clancy & Hogan 1999, IEEE
//   TBME 46:730, find the PDF between Gaussian and Laplacian, nearer Gaussian at higher levels);
// - RMS amplitude proportional to activation (the linear EMG-force assumption of HJ15 eq. 23-24);
// - crosstalk, mains, seeding, electromechanical delay.
#include "sim/synthetic_emg.h"

#include <cmath>
#include <complex>
#include <vector>

#include <gtest/gtest.h>

#include "dsp/butterworth.h"

namespace exotwin {
namespace {

int I(Muscle m) { return static_cast<int>(m); }

// In-place radix-2 FFT (n a power of two).
void Fft(std::vector<std::complex<double>>& a) {
  const size_t n = a.size();
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2 * M_PI / static_cast<double>(len);
    const std::complex<double> wl(std::cos(ang), std::sin(ang));
    for (size_t i = 0; i < n; i += len) {
      std::complex<double> w(1);
      for (size_t k = 0; k < len / 2; ++k) {
        const auto u = a[i + k], v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
        w *= wl;
      }
    }
  }
}

// Welch PSD (Hann, 512-sample segments = 512 ms at 1 kHz as Pincivero et al., 50 % overlap).
std::vector<double> Welch(const std::vector<double>& x, size_t nseg = 512) {
  std::vector<double> psd(nseg / 2 + 1, 0.0);
  for (size_t s = 0; s + nseg <= x.size(); s += nseg / 2) {
    std::vector<std::complex<double>> a(nseg);
    for (size_t k = 0; k < nseg; ++k)
      a[k] = x[s + k] * 0.5 * (1 - std::cos(2 * M_PI * k / (nseg - 1)));
    Fft(a);
    for (size_t k = 0; k <= nseg / 2; ++k) psd[k] += std::norm(a[k]);
  }
  return psd;
}

double MedianFrequency(const std::vector<double>& psd, double fs) {
  double total = 0;
  for (double p : psd) total += p;
  double c = 0;
  const double df = fs / (2.0 * (psd.size() - 1));
  for (size_t k = 0; k < psd.size(); ++k) {
    c += psd[k];
    if (c >= total / 2) return k * df;
  }
  return fs / 2;
}

double BandFraction(const std::vector<double>& psd, double fs, double f0, double f1) {
  double total = 0, in = 0;
  const double df = fs / (2.0 * (psd.size() - 1));
  for (size_t k = 0; k < psd.size(); ++k) {
    total += psd[k];
    if (k * df >= f0 && k * df <= f1) in += psd[k];
  }
  return in / total;
}

std::vector<double> Channel(SyntheticEmg& g, const MuscleVec& e, int c, int n) {
  std::vector<double> x;
  for (int k = 0; k < n; ++k) x.push_back(g.Sample(e)[c]);
  return x;
}

double Rms(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return std::sqrt(s / x.size());
}

SyntheticEmgConfig NoCrosstalk() {
  SyntheticEmgConfig c = DefaultSyntheticEmgConfig();
  c.crosstalk.setIdentity();
  return c;
}

TEST(SyntheticEmg, SameSeedSameBits) {
  SyntheticEmg a(DefaultSyntheticEmgConfig(), 9), b(DefaultSyntheticEmgConfig(), 9),
      c(DefaultSyntheticEmgConfig(), 10);
  const MuscleVec e = MuscleVec::Constant(0.3);
  bool differs = false;
  for (int k = 0; k < 5000; ++k) {
    const MuscleVec xa = a.Sample(e), xb = b.Sample(e), xc = c.Sample(e);
    for (int m = 0; m < kNumMuscles; ++m) {
      ASSERT_EQ(xa[m], xb[m]);  // bit-identical
      differs |= xa[m] != xc[m];
    }
  }
  EXPECT_TRUE(differs);
}

TEST(SyntheticEmg, RelaxedLevelsMatchHayashiAfterGain1000) {
  SyntheticEmg g(DefaultSyntheticEmgConfig(), 1);
  std::vector<MuscleVec> rec = g.Generate(std::vector<MuscleVec>(60000, MuscleVec::Zero()));
  // After the amplifier (gain 1000, 4th-order band-pass 20-450 Hz) the RMS level of a relaxed
  // extensor (VM) is ~0.1 V and of a flexor (ST) ~0.04 V (Hayashi et al., Fig. 7 text).
  const auto bp = dsp::DesignButterworth(4, dsp::BandType::kBandPass, 1000, 20, 450);
  for (Muscle m : {Muscle::kVM, Muscle::kST}) {
    std::vector<double> x;
    for (const auto& v : rec) x.push_back(1000 * v[I(m)]);
    const std::vector<double> y = dsp::FiltFilt(bp, x);
    const double expected = (m == Muscle::kVM) ? 0.1 : 0.04;
    EXPECT_NEAR(Rms(y), expected, 0.05 * expected) << MuscleName(m);
  }
}

// The EXOwheel's Delsys set-up: a relaxed channel reads 3 uV RMS at the electrode (3 mV after gain
// 1000 and the 20-450 Hz band-pass), 0.1-0.2 % of the muscle's MVC level; a full contraction is
// unchanged from the default (the baseline is the only difference).
TEST(SyntheticEmg, ExowheelRelaxedBaselineIsTheDelsysNoiseFloor) {
  const SyntheticEmgConfig cfg = ExowheelSyntheticEmgConfig();
  SyntheticEmg g(cfg, 1);
  std::vector<MuscleVec> rec = g.Generate(std::vector<MuscleVec>(60000, MuscleVec::Zero()));
  const auto bp = dsp::DesignButterworth(4, dsp::BandType::kBandPass, 1000, 20, 450);
  for (int c = 0; c < kNumMuscles; ++c) {
    std::vector<double> x;
    for (const auto& v : rec) x.push_back(1000 * v[c]);
    const double rms = Rms(dsp::FiltFilt(bp, x));
    EXPECT_NEAR(rms, 3e-3, 0.05 * 3e-3) << MuscleName(MuscleAt(c));
    EXPECT_LT(rms / (1000 * cfg.mvc_rms[c]), 0.0025) << MuscleName(MuscleAt(c)) << ": share of MVC";
  }
  const SyntheticEmgConfig hal = DefaultSyntheticEmgConfig();
  EXPECT_EQ(cfg.mvc_rms, hal.mvc_rms);
  EXPECT_EQ(cfg.crosstalk, hal.crosstalk);
  EXPECT_GT(hal.baseline_rms.minCoeff(), 10 * cfg.baseline_rms.maxCoeff());
}

TEST(SyntheticEmg, MedianFrequencyAndBandOfTheSpectrum) {
  SyntheticEmg g(NoCrosstalk(), 2);
  const std::vector<double> x = Channel(g, MuscleVec::Constant(0.5), I(Muscle::kVM), 60000);
  const std::vector<double> psd = Welch(x);
  const double mdf = MedianFrequency(psd, 1000);
  std::printf("[synthetic EMG] VM at 50%% MVC: MDF %.1f Hz, power in 20-450 Hz %.1f %%\n", mdf,
              100 * BandFraction(psd, 1000, 20, 450));
  EXPECT_GE(mdf, 60.0);
  EXPECT_LE(mdf, 120.0);
  EXPECT_GT(BandFraction(psd, 1000, 20, 450), 0.95);
  // After the amplifier's band-pass the median frequency barely moves.
  const auto bp = dsp::DesignButterworth(4, dsp::BandType::kBandPass, 1000, 20, 450);
  const double mdf_amp = MedianFrequency(Welch(dsp::FiltFilt(bp, x)), 1000);
  EXPECT_NEAR(mdf_amp, mdf, 10.0);
}

TEST(SyntheticEmg, AmplitudeIsProportionalToActivationAndNearlyGaussian) {
  const SyntheticEmgConfig cfg = NoCrosstalk();
  std::vector<double> level, rms_signal;
  for (double a : {0.1, 0.25, 0.5, 1.0}) {
    SyntheticEmg g(cfg, 3);
    const std::vector<double> x = Channel(g, MuscleVec::Constant(a), I(Muscle::kVM), 40000);
    const double r = Rms(x), b = cfg.baseline_rms[I(Muscle::kVM)];
    const double sig = std::sqrt(std::max(0.0, r * r - b * b));  // baseline adds in quadrature
    EXPECT_NEAR(sig, a * cfg.mvc_rms[I(Muscle::kVM)], 0.04 * a * cfg.mvc_rms[I(Muscle::kVM)]);
    if (a == 0.5) {
      double m2 = 0, m4 = 0;
      for (double v : x) {
        m2 += v * v;
        m4 += v * v * v * v;
      }
      const double kurt = (m4 / x.size()) / std::pow(m2 / x.size(), 2);
      std::printf("[synthetic EMG] kurtosis at 50%% MVC: %.2f (Gaussian 3, Laplacian 6)\n", kurt);
      EXPECT_NEAR(kurt, 3.0, 0.2);
    }
  }
}

TEST(SyntheticEmg, CrosstalkAndMains) {
  SyntheticEmgConfig cfg = DefaultSyntheticEmgConfig();
  cfg.baseline_rms.setZero();
  SyntheticEmg g(cfg, 4);
  std::vector<double> vm, rf;
  for (int k = 0; k < 40000; ++k) {
    const MuscleVec x = g.Sample(MuscleVec::Unit(I(Muscle::kVM)) * 0.5);
    vm.push_back(x[I(Muscle::kVM)]);
    rf.push_back(x[I(Muscle::kRF)]);
  }
  EXPECT_NEAR(Rms(rf) / Rms(vm), 0.15, 0.005);  // RF channel sees 15 % of VM
  cfg.mains_amplitude = 20e-6;
  cfg.mains_freq = 50;
  SyntheticEmg h(cfg, 4);
  const std::vector<double> x = Channel(h, MuscleVec::Zero(), I(Muscle::kGAS), 8192);
  const std::vector<double> psd = Welch(x);
  const size_t k50 = static_cast<size_t>(std::lround(50.0 / (1000.0 / 512)));
  EXPECT_GT(psd[k50], 100 * psd[k50 + 10]);
  EXPECT_NEAR(Rms(x), 20e-6 / std::sqrt(2.0), 1e-6);
}

TEST(SyntheticEmg, EmgLeadsTheTorqueByTheElectromechanicalDelay) {
  MuscleParams p = PaperMeanMuscleParams();
  MuscleModel muscles(p, 1e-3);
  SyntheticEmgConfig cfg = NoCrosstalk();
  cfg.baseline_rms.setZero();
  SyntheticEmg g(cfg, 5);
  int k_emg = -1, k_torque = -1;
  for (int k = 0; k < 400; ++k) {
    muscles.Step(MuscleVec::Unit(I(Muscle::kVM)) * (k >= 100 ? 0.5 : 0.0));
    const double x = g.Sample(muscles.electrical_activation())[I(Muscle::kVM)];
    const double tau = muscles.Torques({0, -M_PI / 2}, {0, 0}).contraction[1];
    if (k_emg < 0 && std::abs(x) > 0) k_emg = k;
    if (k_torque < 0 && tau > 0) k_torque = k;
  }
  EXPECT_NEAR((k_torque - k_emg) * 1e-3, p.emd, 1.5e-3);
}

}  // namespace
}  // namespace exotwin
