// EMG activity detection of the controllers: the activation threshold of HJ15 eq. 13
// on the band-passed, rectified EMG chi (V). The signal chains themselves (band-pass, rectification,
// linear and RMS envelopes, MVC normalization) are dsp/'s: dsp/emg_envelope.h, dsp/mvc.h.
#pragma once
#include <vector>

namespace exotwin::controller {

// Activation threshold of HJ15 eq. 13: Z = mean + n_sd SD of chi (band-passed, rectified EMG) recorded
// while relaxed; A(k) = 1 if chi(k) > Z.
struct ActivationThreshold {
  double mean = 0, sd = 0, z = 0;  // V
  bool Active(double chi) const { return chi > z; }
};
// Fits the threshold on a relaxed record chi (>= 2 samples). n_sd = 3 in the paper.
ActivationThreshold FitActivationThreshold(const std::vector<double>& chi_relaxed, double n_sd = 3.0);
// Fraction of samples of chi above the threshold (0..1).
double ActiveFraction(const ActivationThreshold& th, const std::vector<double>& chi);

}  // namespace exotwin::controller
