// Butterworth filters as cascades of second-order sections (bilinear transform with pre-warping),
// causal filtering for the real-time path and zero-phase forward-backward filtering for off-line use.
#pragma once
#include <array>
#include <cstddef>
#include <functional>
#include <vector>

namespace exotwin::dsp {

// One second-order section, a0 normalised to 1: H(z) = (b0 + b1 z^-1 + b2 z^-2)/(1 + a1 z^-1 + a2 z^-2).
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
};

enum class BandType { kLowPass, kHighPass, kBandPass };

// Design an order-N Butterworth filter. f_lo/f_hi in Hz (f_hi only for band-pass), fs sample rate, Hz.
// Preconditions: N >= 1, 0 < f < fs/2 (throws std::invalid_argument otherwise). A band-pass of order N
// has 2N poles (as scipy.signal.butter(N, [f_lo, f_hi], 'bandpass')).
std::vector<Biquad> DesignButterworth(int order, BandType type, double fs, double f_lo,
                                      double f_hi = 0.0);

// Complex gain magnitude of the cascade at frequency f (Hz).
double MagnitudeResponse(const std::vector<Biquad>& sos, double fs, double f);

// Causal cascade filter with state (transposed direct form II); real-time safe after construction.
class SosFilter {
 public:
  SosFilter() = default;
  explicit SosFilter(std::vector<Biquad> sos);
  // Filters one sample.
  double Step(double x);
  // Sets the internal state to the steady state for a constant input x (no start-up transient).
  void ResetSteady(double x);
  void Reset();

 private:
  std::vector<Biquad> sos_;
  std::vector<std::array<double, 2>> z_;
};

// Zero-phase filtering (forward then backward), odd-reflection padding of 3*(2*sections+1) samples
// and steady-state initial conditions, like scipy.signal.sosfiltfilt. Inputs shorter than the pad
// length use the whole signal as the pad.
std::vector<double> FiltFilt(const std::vector<Biquad>& sos, const std::vector<double>& x);
// FiltFilt(sos, x) written over x, bit for bit, without a padded copy of the signal.
void FiltFiltInPlace(const std::vector<Biquad>& sos, std::vector<double>& x);
// The same for count signals of one length (*xs[0] .. *xs[count - 1]), each bit for bit as alone,
// filtered a few at a time (faster than one by one). Throws std::invalid_argument for signals of
// different lengths.
void FiltFiltInPlace(const std::vector<Biquad>& sos, std::vector<double>* const* xs, size_t count);
// The same for count (1 .. 8) signals that the caller generates block by block: fill(begin, end) writes the
// raw samples [begin, end) of every signal into (*xs[k])[begin .. end) (each *xs[k] sized n
// beforehand; fill may be asked for a few samples twice and must give the same values). Each block is
// filtered forward while it is still in cache, so a signal crosses memory twice (written, then
// filtered backward) instead of four times. On return *xs[k] is FiltFiltInPlace's result, bit for bit.
void FiltFiltGenerated(const std::vector<Biquad>& sos, std::vector<double>* const* xs, size_t count,
                       const std::function<void(size_t begin, size_t end)>& fill);

}  // namespace exotwin::dsp
