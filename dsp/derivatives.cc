// Zero-phase derivatives: see derivatives.h.
#include "dsp/derivatives.h"

#include "dsp/butterworth.h"

namespace exotwin::dsp {

void GradientInto(const std::vector<double>& x, double dt, std::vector<double>* out) {
  const size_t n = x.size();
  std::vector<double>& d = *out;
  d.assign(n, 0.0);
  if (n < 2) return;
  d[0] = (x[1] - x[0]) / dt;
  d[n - 1] = (x[n - 1] - x[n - 2]) / dt;
  for (size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - x[i - 1]) / (2.0 * dt);
}

std::vector<double> Gradient(const std::vector<double>& x, double dt) {
  std::vector<double> d;
  GradientInto(x, dt, &d);
  return d;
}

void ZeroPhaseRates(const std::vector<double>& x, double dt, double fc, std::vector<double>* first,
                    std::vector<double>* second) {
  std::vector<double>& filtered = *second;  // the low-passed signal, then overwritten by its second derivative
  filtered = x;
  FiltFiltInPlace(DesignButterworth(2, BandType::kLowPass, 1.0 / dt, fc), filtered);
  GradientInto(filtered, dt, first);
  GradientInto(*first, dt, second);
}

Derivatives ZeroPhaseDerivatives(const std::vector<double>& x, double dt, double fc) {
  Derivatives d;
  d.filtered = FiltFilt(DesignButterworth(2, BandType::kLowPass, 1.0 / dt, fc), x);
  d.first = Gradient(d.filtered, dt);
  d.second = Gradient(d.first, dt);
  return d;
}

}  // namespace exotwin::dsp
