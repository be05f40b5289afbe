#include "dsp/butterworth.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

namespace exotwin::dsp {
namespace {

using cd = std::complex<double>;

cd Bilinear(cd s, double fs) { return (2.0 * fs + s) / (2.0 * fs - s); }

cd EvalCascade(const std::vector<Biquad>& sos, cd z) {
  cd h = 1.0;
  const cd zi = 1.0 / z;
  for (const Biquad& s : sos)
    h *= (s.b0 + s.b1 * zi + s.b2 * zi * zi) / (1.0 + s.a1 * zi + s.a2 * zi * zi);
  return h;
}

// One sample through one section with its state (z0, z1) (transposed direct form II); T is
// double or Pair.
template <class T>
inline T StepSection(T b0, T b1, T b2, T a1, T a2, T& z0, T& z1, T x) {
  const T y = b0 * x + z0;
  z0 = b1 * x - a1 * y + z1;
  z1 = b2 * x - a2 * y;
  return y;
}

// Two signals' values, one per lane: SSE2's packed operations are, lane by lane, the IEEE
// operations on one double (x86-64 has no fused multiply-add unless the build asks for it).
using Pair = double __attribute__((vector_size(16)));

// One sample through the cascade with its state z (one pair per section).
inline double StepCascade(const std::vector<Biquad>& sos, std::array<double, 2>* z, double x) {
  for (size_t i = 0; i < sos.size(); ++i) {
    const Biquad& s = sos[i];
    x = StepSection(s.b0, s.b1, s.b2, s.a1, s.a2, z[i][0], z[i][1], x);
  }
  return x;
}

// x[k][0 .. n) of K signals through one section, interleaved sample by sample (two per Pair),
// forward or backward, with the coefficients and the states z[k] held in registers.
template <size_t K>
void RunOneSection(const Biquad& s, std::array<double, 2>* const* z, double* const* x, size_t n, bool backward) {
  constexpr size_t P = K / 2;  // pairs; an odd K leaves one signal on its own
  const double b0 = s.b0, b1 = s.b1, b2 = s.b2, a1 = s.a1, a2 = s.a2;
  const Pair B0 = {b0, b0}, B1 = {b1, b1}, B2 = {b2, b2}, A1 = {a1, a1}, A2 = {a2, a2};
  Pair z0[P + 1], z1[P + 1];
  double z0_odd = 0, z1_odd = 0;
  for (size_t p = 0; p < P; ++p) {
    z0[p] = Pair{z[2 * p][0][0], z[2 * p + 1][0][0]};
    z1[p] = Pair{z[2 * p][0][1], z[2 * p + 1][0][1]};
  }
  if (K % 2) z0_odd = z[K - 1][0][0], z1_odd = z[K - 1][0][1];
  auto step = [&](size_t i) {
    for (size_t p = 0; p < P; ++p) {
      const Pair y = StepSection(B0, B1, B2, A1, A2, z0[p], z1[p], Pair{x[2 * p][i], x[2 * p + 1][i]});
      x[2 * p][i] = y[0], x[2 * p + 1][i] = y[1];
    }
    if (K % 2) x[K - 1][i] = StepSection(b0, b1, b2, a1, a2, z0_odd, z1_odd, x[K - 1][i]);
  };
  if (!backward) {
    for (size_t i = 0; i < n; ++i) step(i);
  } else {
    for (size_t i = n; i-- > 0;) step(i);
  }
  for (size_t p = 0; p < P; ++p) {
    z[2 * p][0][0] = z0[p][0], z[2 * p + 1][0][0] = z0[p][1];
    z[2 * p][0][1] = z1[p][0], z[2 * p + 1][0][1] = z1[p][1];
  }
  if (K % 2) z[K - 1][0][0] = z0_odd, z[K - 1][0][1] = z1_odd;
}

// x[k][0 .. n) of K (1 .. 8) signals through the cascade, interleaved sample by sample (their
// recursions are independent, so the processor overlaps them), forward or backward, states z[k].
void RunCascade(const std::vector<Biquad>& sos, std::array<double, 2>* const* z, double* const* x, size_t K,
                size_t n, bool backward) {
  if (sos.size() == 1) {
    switch (K) {
      case 1: return RunOneSection<1>(sos[0], z, x, n, backward);
      case 2: return RunOneSection<2>(sos[0], z, x, n, backward);
      case 3: return RunOneSection<3>(sos[0], z, x, n, backward);
      case 4: return RunOneSection<4>(sos[0], z, x, n, backward);
      case 5: return RunOneSection<5>(sos[0], z, x, n, backward);
      case 6: return RunOneSection<6>(sos[0], z, x, n, backward);
      case 7: return RunOneSection<7>(sos[0], z, x, n, backward);
      case 8: return RunOneSection<8>(sos[0], z, x, n, backward);
      default: break;
    }
  }
  if (!backward) {
    for (size_t i = 0; i < n; ++i)
      for (size_t k = 0; k < K; ++k) x[k][i] = StepCascade(sos, z[k], x[k][i]);
  } else {
    for (size_t i = n; i-- > 0;)
      for (size_t k = 0; k < K; ++k) x[k][i] = StepCascade(sos, z[k], x[k][i]);
  }
}

// The state z of the cascade's steady state for a constant input x.
inline void ResetCascade(const std::vector<Biquad>& sos, std::array<double, 2>* z, double x) {
  for (size_t i = 0; i < sos.size(); ++i) {
    const Biquad& s = sos[i];
    const double den = 1.0 + s.a1 + s.a2;
    const double y = std::abs(den) > 1e-300 ? x * (s.b0 + s.b1 + s.b2) / den : 0.0;
    z[i][1] = s.b2 * x - s.a2 * y;
    z[i][0] = s.b1 * x - s.a1 * y + z[i][1];
    x = y;
  }
}

}  // namespace

std::vector<Biquad> DesignButterworth(int order, BandType type, double fs, double f_lo,
                                      double f_hi) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("Butterworth: " + what); };
  if (order < 1 || order > 12) bad("order must be in 1..12, got " + std::to_string(order));
  if (!(fs > 0)) bad("sample rate must be > 0");
  if (!(f_lo > 0 && f_lo < fs / 2)) bad("cut-off must be in (0, fs/2)");
  if (type == BandType::kBandPass && !(f_hi > f_lo && f_hi < fs / 2))
    bad("band-pass needs f_lo < f_hi < fs/2");

  // Pre-warped analogue frequencies (rad/s).
  const double w_lo = 2.0 * fs * std::tan(M_PI * f_lo / fs);
  const double w_hi = type == BandType::kBandPass ? 2.0 * fs * std::tan(M_PI * f_hi / fs) : 0.0;

  // Analogue prototype poles on the unit circle, left half plane.
  std::vector<cd> proto;
  for (int k = 0; k < order; ++k)
    proto.push_back(std::polar(1.0, M_PI * (2.0 * k + order + 1) / (2.0 * order)));

  std::vector<cd> poles;  // digital
  double zero_at_plus1 = 0, zero_at_minus1 = 0;
  for (const cd& p : proto) {
    switch (type) {
      case BandType::kLowPass:
        poles.push_back(Bilinear(p * w_lo, fs));
        zero_at_minus1 += 1;
        break;
      case BandType::kHighPass:
        poles.push_back(Bilinear(w_lo / p, fs));
        zero_at_plus1 += 1;
        break;
      case BandType::kBandPass: {
        const double bw = w_hi - w_lo, w0sq = w_lo * w_hi;
        const cd disc = std::sqrt(p * p * bw * bw - 4.0 * w0sq);
        poles.push_back(Bilinear((p * bw + disc) / 2.0, fs));
        poles.push_back(Bilinear((p * bw - disc) / 2.0, fs));
        zero_at_plus1 += 1;
        zero_at_minus1 += 1;
        break;
      }
    }
  }

  // Pair poles: complex ones with their conjugates, real ones two by two.
  std::vector<std::pair<cd, cd>> pairs;
  std::vector<cd> reals;
  for (const cd& p : poles) {
    if (p.imag() > 1e-12) pairs.push_back({p, std::conj(p)});
    else if (std::abs(p.imag()) <= 1e-12) reals.push_back(cd(p.real(), 0.0));
  }
  std::vector<Biquad> sos;
  auto take_zero = [&](double& b1, double& b2, bool second) {
    // Multiplies (1 - z0 z^-1) into the numerator polynomial [1, b1, b2].
    double z0;
    if (zero_at_plus1 >= zero_at_minus1 && zero_at_plus1 > 0) { z0 = 1.0; zero_at_plus1 -= 1; }
    else if (zero_at_minus1 > 0) { z0 = -1.0; zero_at_minus1 -= 1; }
    else return;
    if (!second) b1 = -z0;
    else { b2 = -z0 * b1; b1 = b1 - z0; }
  };
  for (auto& pr : pairs) {
    Biquad s;
    s.a1 = -2.0 * pr.first.real();
    s.a2 = std::norm(pr.first);
    double b1 = 0, b2 = 0;
    take_zero(b1, b2, false);
    take_zero(b1, b2, true);
    s.b0 = 1.0; s.b1 = b1; s.b2 = b2;
    sos.push_back(s);
  }
  for (size_t i = 0; i < reals.size(); i += 2) {
    Biquad s;
    double b1 = 0, b2 = 0;
    if (i + 1 < reals.size()) {
      s.a1 = -(reals[i].real() + reals[i + 1].real());
      s.a2 = reals[i].real() * reals[i + 1].real();
      take_zero(b1, b2, false);
      take_zero(b1, b2, true);
    } else {
      s.a1 = -reals[i].real();
      take_zero(b1, b2, false);
    }
    s.b0 = 1.0; s.b1 = b1; s.b2 = b2;
    sos.push_back(s);
  }

  // Unit gain in the pass band.
  double f_ref = 0.0;
  if (type == BandType::kHighPass) f_ref = fs / 2.0;
  if (type == BandType::kBandPass) f_ref = std::atan(std::sqrt(w_lo * w_hi) / (2.0 * fs)) * fs / M_PI;
  const double gain = std::abs(EvalCascade(sos, std::polar(1.0, 2.0 * M_PI * f_ref / fs)));
  sos[0].b0 /= gain; sos[0].b1 /= gain; sos[0].b2 /= gain;
  return sos;
}

double MagnitudeResponse(const std::vector<Biquad>& sos, double fs, double f) {
  return std::abs(EvalCascade(sos, std::polar(1.0, 2.0 * M_PI * f / fs)));
}

SosFilter::SosFilter(std::vector<Biquad> sos) : sos_(std::move(sos)), z_(sos_.size(), {0.0, 0.0}) {}

double SosFilter::Step(double x) { return StepCascade(sos_, z_.data(), x); }

void SosFilter::ResetSteady(double x) { ResetCascade(sos_, z_.data(), x); }

void SosFilter::Reset() {
  for (auto& z : z_) z = {0.0, 0.0};
}

void FiltFiltInPlace(const std::vector<Biquad>& sos, std::vector<double>* const* xs, size_t count) {
  // Up to kBlock signals at a time (RunCascade); each goes through exactly the operations a padded
  // copy of it would: the odd-reflected extension [head, x, tail] forward, then backward (the
  // head's backward pass only shapes samples that are cropped).
  constexpr size_t kBlock = 8;
  const size_t sections = sos.size();
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t K = std::min(kBlock, count - first);
    const size_t n = xs[first]->size();
    for (size_t k = 1; k < K; ++k)
      if (xs[first + k]->size() != n) throw std::invalid_argument("FiltFiltInPlace: signals of different lengths");
    if (n == 0) continue;
    size_t pad = 3 * (2 * sections + 1);
    if (pad >= n) pad = n - 1;
    double* x[kBlock];
    std::vector<double> head[kBlock], tail[kBlock];
    std::vector<std::array<double, 2>> z[kBlock];
    for (size_t k = 0; k < K; ++k) {
      x[k] = xs[first + k]->data();
      head[k].resize(pad), tail[k].resize(pad);
      for (size_t i = 0; i < pad; ++i) head[k][i] = 2.0 * x[k][0] - x[k][pad - i];
      for (size_t i = 1; i <= pad; ++i) tail[k][i - 1] = 2.0 * x[k][n - 1] - x[k][n - 1 - i];
      z[k].assign(sections, {0.0, 0.0});
      ResetCascade(sos, z[k].data(), pad > 0 ? head[k].front() : x[k][0]);
    }
    double *h[kBlock], *t[kBlock];
    std::array<double, 2>* zk[kBlock];
    for (size_t k = 0; k < K; ++k) h[k] = head[k].data(), t[k] = tail[k].data(), zk[k] = z[k].data();
    RunCascade(sos, zk, h, K, pad, false);
    RunCascade(sos, zk, x, K, n, false);
    RunCascade(sos, zk, t, K, pad, false);
    for (size_t k = 0; k < K; ++k) ResetCascade(sos, z[k].data(), pad > 0 ? tail[k].back() : x[k][n - 1]);
    RunCascade(sos, zk, t, K, pad, true);
    RunCascade(sos, zk, x, K, n, true);
  }
}

void FiltFiltGenerated(const std::vector<Biquad>& sos, std::vector<double>* const* xs, size_t count,
                       const std::function<void(size_t begin, size_t end)>& fill) {
  // FiltFiltInPlace's operations in its order, its forward pass over x cut into blocks (the
  // sections' states carried in z from block to block), the signals interleaved. (FiltFiltInPlace
  // keeps its own whole-signal passes: for signals already in memory the blocks cost more than they
  // save.)
  constexpr size_t kMaxSignals = 8, kFillSamples = 2048;
  if (count == 0) return;
  if (count > kMaxSignals) throw std::invalid_argument("FiltFiltGenerated: more than 8 signals");
  const size_t n = xs[0]->size();
  for (size_t k = 1; k < count; ++k)
    if (xs[k]->size() != n) throw std::invalid_argument("FiltFiltGenerated: signals of different lengths");
  if (n == 0) return;
  const size_t K = count, sections = sos.size();
  size_t pad = 3 * (2 * sections + 1);
  if (pad >= n) pad = n - 1;
  double *x[kMaxSignals], *h[kMaxSignals], *t[kMaxSignals], *xb[kMaxSignals];
  std::vector<double> head[kMaxSignals], tail[kMaxSignals];
  std::vector<std::array<double, 2>> z[kMaxSignals];
  std::array<double, 2>* zk[kMaxSignals];
  // The tail's odd reflection of the raw last pad + 1 samples, before the forward pass overwrites them.
  fill(n - 1 - pad, n);
  for (size_t k = 0; k < K; ++k) {
    x[k] = xs[k]->data();
    head[k].resize(pad), tail[k].resize(pad);
    for (size_t i = 1; i <= pad; ++i) tail[k][i - 1] = 2.0 * x[k][n - 1] - x[k][n - 1 - i];
    z[k].assign(sections, {0.0, 0.0});
    h[k] = head[k].data(), t[k] = tail[k].data(), zk[k] = z[k].data();
  }
  for (size_t b = 0; b < n; b += kFillSamples) {
    const size_t e = std::min(n, b + kFillSamples);
    fill(b, e);
    if (b == 0) {  // the head's odd reflection of the raw first pad + 1 samples (pad < n, pad < e)
      for (size_t k = 0; k < K; ++k) {
        for (size_t i = 0; i < pad; ++i) head[k][i] = 2.0 * x[k][0] - x[k][pad - i];
        ResetCascade(sos, z[k].data(), pad > 0 ? head[k].front() : x[k][0]);
      }
      RunCascade(sos, zk, h, K, pad, false);
    }
    for (size_t k = 0; k < K; ++k) xb[k] = x[k] + b;
    RunCascade(sos, zk, xb, K, e - b, false);
  }
  RunCascade(sos, zk, t, K, pad, false);
  for (size_t k = 0; k < K; ++k) ResetCascade(sos, z[k].data(), pad > 0 ? tail[k].back() : x[k][n - 1]);
  RunCascade(sos, zk, t, K, pad, true);
  RunCascade(sos, zk, x, K, n, true);
}

void FiltFiltInPlace(const std::vector<Biquad>& sos, std::vector<double>& x) {
  std::vector<double>* one = &x;
  FiltFiltInPlace(sos, &one, 1);
}

std::vector<double> FiltFilt(const std::vector<Biquad>& sos, const std::vector<double>& x) {
  std::vector<double> y = x;
  FiltFiltInPlace(sos, y);
  return y;
}

}  // namespace exotwin::dsp
