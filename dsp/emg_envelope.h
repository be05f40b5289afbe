// EMG amplitude chains: band-pass, full-wave rectification, linear envelope (Hwang & Jeon 2015
// sec. 4.3: 4th-order Butterworth 2 Hz low-pass of the rectified signal) in a causal variant for the
// real-time path and a zero-phase variant for off-line calibration and analysis, and the moving RMS
// envelope (HKS05 eq. 1). Input: the amplified EMG in V (after the amplifier's
// gain 1000), sampled at fs (1 kHz unless said). Causal classes are allocation-free after
// construction; the zero-phase functions take whole records.
#pragma once
#include <cmath>
#include <cstddef>
#include <vector>

#include "dsp/butterworth.h"

namespace exotwin::dsp {

// Full-wave rectification |x|.
inline double Rectify(double x) { return std::abs(x); }

// 4th-order Butterworth band-pass f_lo..f_hi (Hz) at fs (Hz): DesignButterworth order 2 (4 poles,
// the paper's "fourth-order" band-pass, as scipy's butter(2, [f_lo, f_hi], 'bandpass')). Default
// 20-450 Hz as the amplifier of Hwang & Jeon (Bagnoli). Precondition: 0 < f_lo < f_hi < fs/2.
std::vector<Biquad> EmgBandPassDesign(double fs = 1000.0, double f_lo = 20.0, double f_hi = 450.0);
// 4th-order Butterworth low-pass at fc (Hz) of the linear envelope. Precondition: 0 < fc < fs/2.
std::vector<Biquad> EnvelopeLowPassDesign(double fs = 1000.0, double fc = 2.0);

// Causal band-pass of EmgBandPassDesign.
class EmgBandPass {
 public:
  explicit EmgBandPass(double fs = 1000.0, double f_lo = 20.0, double f_hi = 450.0);
  double Step(double x);  // V -> V
  void Reset() { f_.Reset(); }

 private:
  SosFilter f_;
};

// Causal linear envelope: |x| then the 4th-order low-pass at fc (default 2 Hz). Group delay ~0.26 s
// at 2 Hz cut-off: use it on line, LinearEnvelopeZeroPhase off line. Precondition: 0 < fc < fs/2.
class LinearEnvelope {
 public:
  explicit LinearEnvelope(double fs = 1000.0, double fc = 2.0);
  double Step(double x);  // x: band-passed EMG (V); returns the envelope (V)
  void Reset() { f_.Reset(); }

 private:
  SosFilter f_;
};

// The causal chain on a whole record (EmgBandPass then LinearEnvelope from rest): what the
// real-time path gives. amplified in V, fs and fc in Hz.
std::vector<double> LinearEnvelopeCausal(const std::vector<double>& amplified, double fs = 1000.0,
                                         double fc = 2.0);

// Zero-phase envelope with given filters: FiltFilt(prefilter), |.|, FiltFilt(lowpass). pad > 0:
// each FiltFilt runs on the signal extended by `pad` odd-reflected samples at both ends (2 x[0] -
// x[pad..1] before, 2 x[n-1] - x[n-1-k] after; pad <= n - 1), cropped after, which keeps the start-up
// transients of a slow low-pass out of a short record. pad = 0: FiltFilt's own padding only.
std::vector<double> ZeroPhaseEnvelope(const std::vector<Biquad>& prefilter, const std::vector<Biquad>& lowpass,
                                      const std::vector<double>& x, size_t pad = 0);
// The same for several signals of one length, filtered together (interleaved), each bit for bit as
// ZeroPhaseEnvelope of it alone; memory: one record per signal and one more. Throws
// std::invalid_argument for signals of different lengths.
std::vector<std::vector<double>> ZeroPhaseEnvelopes(const std::vector<Biquad>& prefilter,
                                                    const std::vector<Biquad>& lowpass,
                                                    const std::vector<const std::vector<double>*>& xs, size_t pad = 0);

// The paper's off-line chain for one channel of amplified EMG (V): zero-phase band-pass 20-450 Hz
// (EmgBandPassDesign), rectification, zero-phase low-pass at fc (EnvelopeLowPassDesign, 2 Hz in the
// paper). Zero phase (effective order doubled, magnitude squared): the paper does not say whether its
// envelope was; lag between EMG and torque would bias the calibration. Preconditions as the designs.
std::vector<double> LinearEnvelopeZeroPhase(const std::vector<double>& amplified, double fs = 1000.0,
                                            double fc = 2.0);

// Moving RMS over the last T seconds (HKS05 eq. 1: E(t) = sqrt(1/T int_{t-T}^t m^2)), causal.
// Hayashi gives no T; default 0.1 s (our choice: ripple < 10 % for 20-450 Hz EMG, delay T/2).
// Running sum of squares with periodic exact recomputation (no drift). Precondition: T*fs >= 1
// (throws std::invalid_argument otherwise).
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

}  // namespace exotwin::dsp
