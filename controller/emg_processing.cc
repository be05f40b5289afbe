// EMG processing: see emg_processing.h.
#include "controller/emg_processing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace exotwin {

EmgBandPass::EmgBandPass(double fs, double f_lo, double f_hi)
    : f_(dsp::DesignButterworth(2, dsp::BandType::kBandPass, fs, f_lo, f_hi)) {}
// (order 2 band-pass = 4 poles = the "fourth-order" band-pass of the paper, as scipy's butter(2, ...))

double EmgBandPass::Step(double x) { return f_.Step(x); }

LinearEnvelope::LinearEnvelope(double fs, double fc)
    : f_(dsp::DesignButterworth(4, dsp::BandType::kLowPass, fs, fc)) {}

double LinearEnvelope::Step(double x) { return f_.Step(Rectify(x)); }

std::vector<double> LinearEnvelopeOffline(const std::vector<double>& x, double fs, double fc) {
  std::vector<double> r(x.size());
  for (size_t k = 0; k < x.size(); ++k) r[k] = Rectify(x[k]);
  return dsp::FiltFilt(dsp::DesignButterworth(4, dsp::BandType::kLowPass, fs, fc), r);
}

std::vector<double> LinearEnvelopeCausal(const std::vector<double>& x, double fs, double fc) {
  EmgBandPass bp(fs);
  LinearEnvelope le(fs, fc);
  std::vector<double> y(x.size());
  for (size_t k = 0; k < x.size(); ++k) y[k] = le.Step(bp.Step(x[k]));
  return y;
}

std::vector<double> BandPassOffline(const std::vector<double>& x, double fs, double f_lo, double f_hi) {
  return dsp::FiltFilt(dsp::DesignButterworth(2, dsp::BandType::kBandPass, fs, f_lo, f_hi), x);
}

RmsEnvelope::RmsEnvelope(double fs, double T) {
  const long n = std::lround(T * fs);
  if (n < 1) throw std::invalid_argument("RmsEnvelope: window T*fs must be >= 1 sample");
  buf_.assign(static_cast<size_t>(n), 0.0);
}

void RmsEnvelope::Reset() {
  std::fill(buf_.begin(), buf_.end(), 0.0);
  head_ = count_ = since_recompute_ = 0;
  sum_ = 0;
}

double RmsEnvelope::Step(double x) {
  const double x2 = x * x;
  sum_ += x2 - buf_[head_];
  buf_[head_] = x2;
  head_ = (head_ + 1) % buf_.size();
  count_ = std::min(count_ + 1, buf_.size());
  if (++since_recompute_ >= buf_.size()) {  // exact sum once per window: bounded rounding drift
    since_recompute_ = 0;
    sum_ = 0;
    for (double v : buf_) sum_ += v;
  }
  // Before the window is full, average over the samples seen (eq. 1 with t - T < 0 clipped).
  return std::sqrt(std::max(0.0, sum_) / static_cast<double>(count_));
}

double MvcFromPeaks(const std::vector<double>& env, double fs, int n, double min_sep_s) {
  if (n < 1) throw std::invalid_argument("MvcFromPeaks: n must be >= 1");
  std::vector<std::pair<double, size_t>> peaks;
  for (size_t k = 1; k + 1 < env.size(); ++k)
    if (env[k] > env[k - 1] && env[k] >= env[k + 1]) peaks.push_back({env[k], k});
  std::sort(peaks.begin(), peaks.end(), [](auto& a, auto& b) { return a.first > b.first; });
  const double sep = min_sep_s * fs;
  std::vector<std::pair<double, size_t>> chosen;
  for (const auto& p : peaks) {
    bool far = true;
    for (const auto& c : chosen)
      far &= std::abs(static_cast<double>(p.second) - static_cast<double>(c.second)) >= sep;
    if (far) chosen.push_back(p);
    if (static_cast<int>(chosen.size()) == n) break;
  }
  if (static_cast<int>(chosen.size()) < n)
    throw std::invalid_argument("MvcFromPeaks: fewer separated peaks than requested");
  double s = 0;
  for (const auto& c : chosen) s += c.first;
  return s / n;
}

std::vector<double> NormalizeToMvc(const std::vector<double>& env, double mvc) {
  if (!(mvc > 0)) throw std::invalid_argument("NormalizeToMvc: mvc must be > 0");
  std::vector<double> y(env.size());
  for (size_t k = 0; k < env.size(); ++k) y[k] = env[k] / mvc;
  return y;
}

ActivationThreshold FitActivationThreshold(const std::vector<double>& chi, double n_sd) {
  if (chi.size() < 2) throw std::invalid_argument("FitActivationThreshold: need >= 2 samples");
  double s = 0;
  for (double v : chi) s += v;
  const double mean = s / chi.size();
  double s2 = 0;
  for (double v : chi) s2 += (v - mean) * (v - mean);
  ActivationThreshold th;
  th.mean = mean;
  th.sd = std::sqrt(s2 / (chi.size() - 1));
  th.z = mean + n_sd * th.sd;
  return th;
}

double ActiveFraction(const ActivationThreshold& th, const std::vector<double>& chi) {
  if (chi.empty()) return 0;
  size_t n = 0;
  for (double v : chi) n += th.Active(v) ? 1 : 0;
  return static_cast<double>(n) / chi.size();
}

}  // namespace exotwin
