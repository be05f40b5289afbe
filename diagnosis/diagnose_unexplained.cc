#include "diagnosis/diagnose_unexplained.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "dsp/butterworth.h"
#include "dsp/statistics.h"

namespace exotwin {

namespace {


// Dominant frequency (Hz) of x[a, b) by a direct DFT of a strided copy, 0.05 .. 25 Hz.
double DominantHz(const std::vector<double>& t, const std::vector<double>& x, size_t a, size_t b) {
  const size_t stride = std::max<size_t>(1, (b - a) / 8000);
  std::vector<double> tt, xx;
  double mean = 0;
  for (size_t i = a; i < b; i += stride) tt.push_back(t[i]), xx.push_back(x[i]), mean += x[i];
  mean /= static_cast<double>(xx.size());
  const double T = tt.back() - tt.front();
  const double fmax = std::min(25.0, 0.5 * static_cast<double>(xx.size()) / std::max(T, 1e-9));
  double best = 0, best_f = 0;
  for (double f = std::max(0.05, 1.0 / std::max(T, 1e-9)); f <= fmax; f += 0.5 / std::max(T, 1.0)) {
    double re = 0, im = 0;
    for (size_t i = 0; i < xx.size(); ++i) {
      const double ph = 2 * M_PI * f * tt[i];
      re += (xx[i] - mean) * std::cos(ph), im += (xx[i] - mean) * std::sin(ph);
    }
    if (re * re + im * im > best) best = re * re + im * im, best_f = f;
  }
  return best_f;
}

}  // namespace

std::optional<UnexplainedStructure> StructureLeft(const HeldOutResidual& r, int joint, double noise, double floor,
                                                  double rmse_before) {
  static const char* kJoint[2] = {"hip", "knee"};
  const double fs = r.fs;
  std::vector<double> e(r.e.begin() + static_cast<long>(r.a), r.e.begin() + static_cast<long>(r.b));
  std::vector<double> elp = e;
  if (fs > 12) elp = dsp::FiltFilt(dsp::DesignButterworth(2, dsp::BandType::kLowPass, fs, 5.0), e);
  double mean = 0, rms = 0;
  for (double v : elp) mean += v;
  mean /= static_cast<double>(elp.size());
  for (double v : elp) rms += (v - mean) * (v - mean);
  rms = std::sqrt(rms / static_cast<double>(elp.size()));
  const double white_lp = noise * std::sqrt(std::min(1.0, 10.0 / fs));
  if (!(rms > std::max(4.0 * white_lp, floor) && rms > 0.15 * rmse_before)) return std::nullopt;
  UnexplainedStructure u;
  u.joint = kJoint[joint];
  u.rms = rms;
  u.dominant_hz = DominantHz(r.t, r.e, r.a, r.b);
  u.corr_q = Pearson(r.e, r.q, r.a, r.b);
  u.corr_qd = Pearson(r.e, r.qd, r.a, r.b);
  u.corr_qdd = Pearson(r.e, r.qdd, r.a, r.b);
  u.corr_t = Pearson(r.e, r.t, r.a, r.b);
  const double cs[4] = {std::abs(u.corr_q), std::abs(u.corr_qd), std::abs(u.corr_qdd), std::abs(u.corr_t)};
  const char* what[4] = {"angle", "velocity", "acceleration", "time (drift)"};
  const int k = static_cast<int>(std::max_element(cs, cs + 4) - cs);
  u.hint = cs[k] > 0.3 ? std::string("follows the ") + what[k]
                       : "not a function of angle, velocity, acceleration or time alone";
  return u;
}

}  // namespace exotwin
