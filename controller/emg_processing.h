// EMG processing of the controllers (issue 6, item 3): band-pass, full-wave rectification, linear
// envelope (Hwang & Jeon 2015: 4th-order Butterworth 2 Hz low-pass of the rectified signal), RMS
// envelope (Hayashi et al. eq. 1), MVC normalization, activation threshold (Hwang & Jeon eq. 13).
// Input: the amplified EMG in V (after the amplifier's gain 1000), sampled at fs (1 kHz).
// Real-time classes are allocation-free after construction; off-line functions take whole records.
#pragma once
#include <cstddef>
#include <vector>

#include "dsp/butterworth.h"

namespace exotwin {

// 4th-order Butterworth band-pass f_lo..f_hi (Hz) at fs (Hz), causal. Default 20-450 Hz as the
// amplifier of Hwang & Jeon (Bagnoli). Precondition: 0 < f_lo < f_hi < fs/2.
class EmgBandPass {
 public:
  explicit EmgBandPass(double fs = 1000.0, double f_lo = 20.0, double f_hi = 450.0);
  double Step(double x);  // V -> V
  void Reset() { f_.Reset(); }

 private:
  dsp::SosFilter f_;
};

// Full-wave rectification |x|.
inline double Rectify(double x) { return x < 0 ? -x : x; }

// Causal linear envelope: |x| then a 4th-order Butterworth low-pass at fc (default 2 Hz, Hwang &
// Jeon section 4.3). Group delay ~0.26 s at 2 Hz cut-off: use it on line, LinearEnvelopeOffline off
// line. Precondition: 0 < fc < fs/2.
class LinearEnvelope {
 public:
  explicit LinearEnvelope(double fs = 1000.0, double fc = 2.0);
  double Step(double x);  // x: band-passed EMG (V); returns the envelope (V)
  void Reset() { f_.Reset(); }

 private:
  dsp::SosFilter f_;
};

// Off-line zero-phase linear envelope: |x| then forward-backward 4th-order low-pass (effective
// order 8, magnitude squared; the paper does not say whether its envelope was zero-phase; we use
// it for the off-line calibration, where lag between EMG and torque would bias alpha).
std::vector<double> LinearEnvelopeOffline(const std::vector<double>& x, double fs = 1000.0,
                                          double fc = 2.0);

// Moving RMS over the last T seconds (Hayashi eq. 1: E(t) = sqrt(1/T int_{t-T}^t m^2)), causal.
// Hayashi gives no T; default 0.1 s (our choice: ripple < 10 % for 20-450 Hz EMG, delay T/2).
// Running sum of squares with periodic exact recomputation (no drift). Precondition: T*fs >= 1.
class RmsEnvelope {
 public:
  explicit RmsEnvelope(double fs = 1000.0, double T = 0.1);
  double Step(double x);  // V -> V
  void Reset();
  size_t window() const { return buf_.size(); }

 private:
  std::vector<double> buf_;
  size_t head_ = 0, count_ = 0, since_recompute_ = 0;
  double sum_ = 0;
};

// Applies band-pass + linear envelope (causal) to a whole record: what the real-time path gives.
std::vector<double> LinearEnvelopeCausal(const std::vector<double>& x, double fs = 1000.0,
                                         double fc = 2.0);
// Band-pass (zero-phase, off-line) of a whole record, 4th order f_lo..f_hi.
std::vector<double> BandPassOffline(const std::vector<double>& x, double fs = 1000.0,
                                    double f_lo = 20.0, double f_hi = 450.0);

// MVC value of an envelope record: the mean of the n highest local peaks at least min_sep_s apart
// (Hwang & Jeon: "the average of the three highest EMG peaks" over three MVC trials). Throws
// std::invalid_argument if fewer than n peaks exist or n < 1.
double MvcFromPeaks(const std::vector<double>& envelope, double fs = 1000.0, int n = 3,
                    double min_sep_s = 1.0);

// Normalized envelope LE = envelope / mvc (fraction of MVC). Precondition: mvc > 0.
std::vector<double> NormalizeToMvc(const std::vector<double>& envelope, double mvc);

// Activation threshold of eq. (13): Z = mean + n_sd SD of chi (band-passed, rectified EMG) recorded
// while relaxed; A(k) = 1 if chi(k) > Z.
struct ActivationThreshold {
  double mean = 0, sd = 0, z = 0;  // V
  bool Active(double chi) const { return chi > z; }
};
// Fits the threshold on a relaxed record chi (>= 2 samples). n_sd = 3 in the paper.
ActivationThreshold FitActivationThreshold(const std::vector<double>& chi_relaxed, double n_sd = 3.0);
// Fraction of samples of chi above the threshold (0..1).
double ActiveFraction(const ActivationThreshold& th, const std::vector<double>& chi);

}  // namespace exotwin
