// Velocity and acceleration of a sampled signal: zero-phase low-pass, then central differences.
// The paper's off-line chain (Hwang & Jeon 2015 sec. 3.2: 2nd-order Butterworth at 20 Hz, zero
// phase), shared by the analysis (measured data), the HAL passive identification (HKS05 eq. 14-15)
// and whoever needs qd, qdd from recorded angles. Uniform sampling only: resampling a non-uniform
// record is the caller's business.
#pragma once
#include <cstddef>
#include <vector>

namespace exotwin::dsp {

// Numerical derivative with central differences (second order inside, one-sided at the ends).
// dt > 0 uniform sample period (s); returns d x / dt per sample (0 everywhere if size < 2).
std::vector<double> Gradient(const std::vector<double>& x, double dt);
// The same written into *out (resized to x's size; its storage reused); out must not be &x.
void GradientInto(const std::vector<double>& x, double dt, std::vector<double>* out);

// A signal low-passed and its first two time derivatives, one value per sample.
struct Derivatives {
  std::vector<double> filtered;  // x after the zero-phase low-pass (unit of x)
  std::vector<double> first;     // d/dt of filtered (unit of x per s)
  std::vector<double> second;    // d/dt of first (unit of x per s^2)
};

// x sampled every dt (s): zero-phase (forward-backward, FiltFilt) 2nd-order Butterworth low-pass at
// fc (Hz), then Gradient twice. Preconditions: dt > 0, 0 < fc < 1/(2 dt) (DesignButterworth throws
// std::invalid_argument otherwise), x non-empty.
Derivatives ZeroPhaseDerivatives(const std::vector<double>& x, double dt, double fc);

// ZeroPhaseDerivatives(x, dt, fc).first and .second, bit for bit, into *first and *second (their
// storage reused) without a third record-long vector: the low-passed signal lives in *second until its
// second derivative replaces it. first, second and &x distinct.
void ZeroPhaseRates(const std::vector<double>& x, double dt, double fc, std::vector<double>* first,
                    std::vector<double>* second);

}  // namespace exotwin::dsp
