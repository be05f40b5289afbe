// EMG amplitude chains: see emg_envelope.h.
#include "dsp/emg_envelope.h"

#include <algorithm>
#include <stdexcept>

namespace exotwin::dsp {
namespace {

// Each *xs[k] (all of one length n) replaced by the FiltFilt of itself extended by `pad` odd-reflected
// samples at both ends, cropped back to n (a padded copy made per signal while the others wait: a
// long record costs one record of memory per signal and one more); the signals filtered together,
// each bit for bit as alone (FiltFiltInPlace). pad 0: FiltFilt's own padding.
void PaddedFiltFiltInPlace(const std::vector<Biquad>& sos, std::vector<double>* const* xs, size_t count, size_t pad) {
  if (count == 0 || xs[0]->empty()) return;
  const size_t n = xs[0]->size();
  pad = std::min(pad, n - 1);
  if (pad > 0)
    for (size_t k = 0; k < count; ++k) {
      const std::vector<double>& x = *xs[k];
      std::vector<double> y;
      y.reserve(n + 2 * pad);
      for (size_t i = pad; i >= 1; --i) y.push_back(2 * x[0] - x[i]);
      y.insert(y.end(), x.begin(), x.end());
      for (size_t i = 1; i <= pad; ++i) y.push_back(2 * x[n - 1] - x[n - 1 - i]);
      *xs[k] = std::move(y);
    }
  FiltFiltInPlace(sos, xs, count);
  if (pad > 0)
    for (size_t k = 0; k < count; ++k) {
      std::vector<double>& y = *xs[k];
      y.erase(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(pad));
      y.resize(n);
    }
}

}  // namespace

std::vector<Biquad> EmgBandPassDesign(double fs, double f_lo, double f_hi) {
  return DesignButterworth(2, BandType::kBandPass, fs, f_lo, f_hi);
}

std::vector<Biquad> EnvelopeLowPassDesign(double fs, double fc) {
  return DesignButterworth(4, BandType::kLowPass, fs, fc);
}

EmgBandPass::EmgBandPass(double fs, double f_lo, double f_hi) : f_(EmgBandPassDesign(fs, f_lo, f_hi)) {}

double EmgBandPass::Step(double x) { return f_.Step(x); }

LinearEnvelope::LinearEnvelope(double fs, double fc) : f_(EnvelopeLowPassDesign(fs, fc)) {}

double LinearEnvelope::Step(double x) { return f_.Step(Rectify(x)); }

std::vector<double> LinearEnvelopeCausal(const std::vector<double>& x, double fs, double fc) {
  EmgBandPass bp(fs);
  LinearEnvelope le(fs, fc);
  std::vector<double> y(x.size());
  for (size_t k = 0; k < x.size(); ++k) y[k] = le.Step(bp.Step(x[k]));
  return y;
}

std::vector<double> ZeroPhaseEnvelope(const std::vector<Biquad>& prefilter, const std::vector<Biquad>& lowpass,
                                      const std::vector<double>& x, size_t pad) {
  return std::move(ZeroPhaseEnvelopes(prefilter, lowpass, {&x}, pad)[0]);
}

std::vector<std::vector<double>> ZeroPhaseEnvelopes(const std::vector<Biquad>& prefilter,
                                                    const std::vector<Biquad>& lowpass,
                                                    const std::vector<const std::vector<double>*>& xs, size_t pad) {
  std::vector<std::vector<double>> y(xs.size());
  std::vector<std::vector<double>*> p(xs.size());
  for (size_t k = 0; k < xs.size(); ++k) {
    if (xs[k]->size() != xs[0]->size()) throw std::invalid_argument("ZeroPhaseEnvelopes: signals of different lengths");
    y[k] = *xs[k], p[k] = &y[k];
  }
  PaddedFiltFiltInPlace(prefilter, p.data(), p.size(), pad);
  for (std::vector<double>& v : y)
    for (double& e : v) e = Rectify(e);
  PaddedFiltFiltInPlace(lowpass, p.data(), p.size(), pad);
  return y;
}

std::vector<double> LinearEnvelopeZeroPhase(const std::vector<double>& x, double fs, double fc) {
  return ZeroPhaseEnvelope(EmgBandPassDesign(fs), EnvelopeLowPassDesign(fs, fc), x);
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
  // Before the window is full, average over the samples seen (HKS05 eq. 1 with t - T < 0 clipped).
  return std::sqrt(std::max(0.0, sum_) / static_cast<double>(count_));
}

}  // namespace exotwin::dsp
