// Lee & Sankai stress metrics, LS05 eq. 12-18: see stress_metrics.h.
#include "runner/stress_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace exotwin {

double IntegratedMyoelectricity(const std::vector<double>& m, double dt) {
  double s = 0;
  for (double v : m) s += std::abs(v) * dt;  // LS05 eq. 15/16
  return s;
}

double MeanAbsMoment(const std::vector<double>& tau_m, double dt) {
  if (tau_m.empty() || !(dt > 0)) throw std::invalid_argument("MeanAbsMoment: empty record or dt <= 0");
  return IntegratedMyoelectricity(tau_m, dt) / (tau_m.size() * dt);  // LS05 eq. 12
}

std::vector<double> NormalizeByMax(const std::vector<double>& J) {
  if (J.empty()) throw std::invalid_argument("NormalizeByMax: empty");
  const double mx = *std::max_element(J.begin(), J.end());  // LS05 eq. 17/18
  if (!(mx > 0)) throw std::invalid_argument("NormalizeByMax: maximum must be > 0");
  std::vector<double> out;
  for (double v : J) out.push_back(v / mx);  // LS05 eq. 13/14
  return out;
}

size_t ArgMin(const std::vector<double>& v) {
  if (v.empty()) throw std::invalid_argument("ArgMin: empty");
  return static_cast<size_t>(std::min_element(v.begin(), v.end()) - v.begin());
}

}  // namespace exotwin
