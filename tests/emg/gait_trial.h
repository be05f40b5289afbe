// A gait-like EMG recording for the tests of emg/ (envelopes and angles; the moments are the test's),
// and the R^2 the tests score predictions with.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/rng.h"
#include "emg/emg_torque_model.h"

namespace exotwin {

// Gait-like envelopes and angles (tests of emg/): 40 s at 100 Hz, five channels (vas_lat_r,
// rect_fem_r, semimem_r, bifemlh_r, med_gas_r) bursting phase-locked to strides; each trial has its own
// cadence, burst amplitudes and timing per channel, and every stride varies around them (amplitude,
// timing); hip 0.1 + 0.35 sin, knee -0.65 - 0.45 sin(. + 1.2) rad, scaled per stride. No moments:
// the caller applies its law, drawing its noise from `rng` (which has drawn the trial).
inline EmgRecording GaitEnvelopesAndAngles(NormalRng<NormalPolar>& rng, const std::string& source) {
  EmgRecording r;
  r.source = source;
  const double fs = 100, T = 40;
  const size_t n = static_cast<size_t>(T * fs);
  const double cadence = rng.Uniform(0.8, 1.0);  // strides/s
  const char* ch[] = {"vas_lat_r", "rect_fem_r", "semimem_r", "bifemlh_r", "med_gas_r"};
  const Muscle mu[] = {Muscle::kVM, Muscle::kRF, Muscle::kST, Muscle::kST, Muscle::kGAS};
  const double phase[] = {0.05, 0.55, 0.85, 0.92, 0.35};   // burst centres, fraction of the stride
  const double width[] = {0.10, 0.07, 0.09, 0.08, 0.10};   // Gaussian SD, fraction of the stride
  double amp[5], shift[5];
  for (int c = 0; c < 5; ++c) amp[c] = rng.Uniform(0.2, 0.6), shift[c] = rng.Uniform(-0.04, 0.04);
  // Per-stride variation, drawn stride by stride.
  const int strides = static_cast<int>(T * cadence) + 3;
  std::vector<std::array<double, 5>> sa(strides), sp(strides);
  std::vector<double> qa(strides);
  for (int k = 0; k < strides; ++k) {
    for (int c = 0; c < 5; ++c) sa[k][c] = std::max(0.2, 1 + 0.3 * rng.Normal()), sp[k][c] = 0.02 * rng.Normal();
    qa[k] = 1 + 0.1 * rng.Normal();
  }
  r.channels.assign(ch, ch + 5);
  r.muscle.assign(mu, mu + 5);
  r.missing = {"GMAX"};
  r.e.assign(5, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs, s = t * cadence;
    const int k = static_cast<int>(s);
    const double ph = s - k;
    r.t.push_back(t);
    for (int c = 0; c < 5; ++c) {
      double e = 0.01;
      for (int dk = -1; dk <= 1; ++dk) {  // the bursts of this stride and its neighbours
        const int kk = std::clamp(k + dk, 0, strides - 1);
        const double x = ph - dk - (phase[c] + shift[c] + sp[kk][c]);
        e += amp[c] * sa[kk][c] * std::exp(-0.5 * x * x / (width[c] * width[c]));
      }
      r.e[c][i] = e;
    }
    const double w = 2 * M_PI * cadence;
    r.q[0].push_back(0.1 + 0.35 * qa[k] * std::sin(w * t));
    r.qd[0].push_back(0.35 * qa[k] * w * std::cos(w * t));
    r.q[1].push_back(-0.65 - 0.45 * qa[k] * std::sin(w * t + 1.2));
    r.qd[1].push_back(-0.45 * qa[k] * w * std::cos(w * t + 1.2));
    // The ankle (the gastrocnemius' path): -10..+16 deg, as in walking.
    r.q_ankle.push_back(0.05 + 0.18 * qa[k] * std::sin(w * t - 0.6));
    r.qd_ankle.push_back(0.18 * qa[k] * w * std::cos(w * t - 0.6));
  }
  return r;
}

// R^2 of p against y over every sample (emg_torque_model.h ScoreSamples).
inline double R2(const std::vector<double>& y, const std::vector<double>& p) {
  std::vector<size_t> all(y.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  double r2, rms;
  ScoreSamples(y, p, all, &r2, &rms);
  return r2;
}

}  // namespace exotwin
