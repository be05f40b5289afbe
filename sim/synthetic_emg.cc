// Synthetic surface EMG: see synthetic_emg.h for the model and its sources.
#include "sim/synthetic_emg.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace exotwin {
namespace {

constexpr double kPi = 3.14159265358979323846;

// RMS of the cascade's output for unit-variance white input: sqrt(sum of h^2) of its impulse response.
double NoiseGain(const std::vector<dsp::Biquad>& sos, double fs) {
  dsp::SosFilter f(sos);
  double s2 = 0;
  const long n = static_cast<long>(20 * fs);
  for (long k = 0; k < n; ++k) {
    const double h = f.Step(k == 0 ? 1.0 : 0.0);
    s2 += h * h;
  }
  return std::sqrt(s2);
}

std::vector<dsp::Biquad> Cascade(std::vector<dsp::Biquad> a, const std::vector<dsp::Biquad>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

SyntheticEmgConfig DefaultSyntheticEmgConfig() {
  SyntheticEmgConfig c;
  c.mvc_rms << 1.5e-3, 3.0e-3, 2.5e-3, 2.5e-3, 2.5e-3;
  const auto I = [](Muscle m) { return static_cast<int>(m); };
  auto& X = c.crosstalk;
  X.setIdentity();
  X(I(Muscle::kVM), I(Muscle::kRF)) = X(I(Muscle::kRF), I(Muscle::kVM)) = 0.15;
  X(I(Muscle::kST), I(Muscle::kGAS)) = X(I(Muscle::kGAS), I(Muscle::kST)) = 0.08;
  X(I(Muscle::kGMAX), I(Muscle::kST)) = X(I(Muscle::kST), I(Muscle::kGMAX)) = 0.05;
  return c;
}

SyntheticEmgConfig ExowheelSyntheticEmgConfig() {
  SyntheticEmgConfig c = DefaultSyntheticEmgConfig();
  c.baseline_rms = MuscleVec::Constant(3.0e-6);
  return c;
}

SyntheticEmg::SyntheticEmg(const SyntheticEmgConfig& config, uint64_t seed) : cfg_(config) {
  if (!(cfg_.f_hp > 0) || !(cfg_.f_lp > cfg_.f_hp) || !(cfg_.fs > 2 * cfg_.f_lp))
    throw std::invalid_argument("SyntheticEmg: need 0 < f_hp < f_lp < fs/2");
  shape_sos_ = Cascade(dsp::DesignButterworth(2, dsp::BandType::kHighPass, cfg_.fs, cfg_.f_hp),
                       dsp::DesignButterworth(2, dsp::BandType::kLowPass, cfg_.fs, cfg_.f_lp));
  const double f_hi = std::min(450.0, 0.45 * cfg_.fs);
  base_sos_ = dsp::DesignButterworth(2, dsp::BandType::kBandPass, cfg_.fs, 20.0, f_hi);
  shape_gain_ = 1.0 / NoiseGain(shape_sos_, cfg_.fs);
  base_gain_ = 1.0 / NoiseGain(base_sos_, cfg_.fs);
  for (int c = 0; c < kNumMuscles; ++c) {
    shape_.emplace_back(shape_sos_);
    base_.emplace_back(base_sos_);
    z_muscle_.emplace_back(MixSeed(MixSeed(seed ^ (0x100ULL + c))));
    z_base_.emplace_back(MixSeed(MixSeed(seed ^ (0x200ULL + c))));
  }
  MuscleRng ph(MixSeed(MixSeed(seed ^ 0x300ULL)));
  mains_phase_ = 2 * kPi * ph.Uniform();
}

MuscleVec SyntheticEmg::Sample(const MuscleVec& e) {
  MuscleVec src, x;
  for (int m = 0; m < kNumMuscles; ++m) {
    const double n = shape_gain_ * shape_[m].Step(z_muscle_[m].Normal());
    src[m] = std::min(1.0, std::max(0.0, e[m])) * cfg_.mvc_rms[m] * n;
  }
  x = cfg_.crosstalk * src;
  const double mains =
      cfg_.mains_amplitude * std::sin(2 * kPi * cfg_.mains_freq * t_ + mains_phase_);
  for (int c = 0; c < kNumMuscles; ++c)
    x[c] += cfg_.baseline_rms[c] * base_gain_ * base_[c].Step(z_base_[c].Normal()) + mains;
  ++k_;
  t_ = static_cast<double>(k_) / cfg_.fs;
  return x;
}

std::vector<MuscleVec> SyntheticEmg::Generate(const std::vector<MuscleVec>& e) {
  std::vector<MuscleVec> out;
  out.reserve(e.size());
  for (const auto& v : e) out.push_back(Sample(v));
  return out;
}

}  // namespace exotwin
