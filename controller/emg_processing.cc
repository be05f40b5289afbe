// EMG activity detection: see emg_processing.h.
#include "controller/emg_processing.h"

#include <cmath>
#include <stdexcept>

namespace exotwin::controller {

ActivationThreshold FitActivationThreshold(const std::vector<double>& chi, double n_sd) {
  if (chi.size() < 2) throw std::invalid_argument("FitActivationThreshold: need >= 2 samples");
  double s = 0;
  for (double v : chi) s += v;
  const double mean = s / chi.size();
  double s2 = 0;
  for (double v : chi) s2 += (v - mean) * (v - mean);
  ActivationThreshold th;
  th.mean = mean;
  th.sd = std::sqrt(s2 / (chi.size() - 1));
  th.z = mean + n_sd * th.sd;
  return th;
}

double ActiveFraction(const ActivationThreshold& th, const std::vector<double>& chi) {
  if (chi.empty()) return 0;
  size_t n = 0;
  for (double v : chi) n += th.Active(v) ? 1 : 0;
  return static_cast<double>(n) / chi.size();
}

}  // namespace exotwin::controller
