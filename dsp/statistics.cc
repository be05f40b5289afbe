#include "dsp/statistics.h"

#include <algorithm>
#include <cmath>

namespace exotwin {

double Pearson(const std::vector<double>& x, const std::vector<double>& y, size_t a, size_t b) {
  if (b <= a) return 0.0;
  double mx = 0, my = 0;
  const double n = static_cast<double>(b - a);
  for (size_t i = a; i < b; ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = a; i < b; ++i) {
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

double AutocorrelationLength(const double* x, size_t n) {
  if (n < 2) return 1.0;
  double mean = 0;
  for (size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  double v = 0;
  for (size_t i = 0; i < n; ++i) v += (x[i] - mean) * (x[i] - mean);
  if (!(v > 0)) return 1.0;
  double tau = 1.0;
  for (size_t lag = 1; lag < std::min<size_t>(n / 4, 2000); ++lag) {
    double c = 0;
    for (size_t i = 0; i + lag < n; ++i) c += (x[i] - mean) * (x[i + lag] - mean);
    const double rho = c / v;
    if (rho < 0.05) break;
    tau += 2 * rho;
  }
  return std::max(tau, 1.0);
}

double Percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return std::nan("");
  const double pos = p * static_cast<double>(sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

double PercentileInPlace(std::vector<double>& values, double p) {
  if (values.empty()) return std::nan("");
  const double pos = p * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const auto at_lo = values.begin() + static_cast<long>(lo);
  std::nth_element(values.begin(), at_lo, values.end());
  // The sorted order's next value: the least of those the selection placed after lo.
  const double v_lo = *at_lo, v_hi = lo + 1 < values.size() ? *std::min_element(at_lo + 1, values.end()) : v_lo;
  return v_lo + (pos - static_cast<double>(lo)) * (v_hi - v_lo);
}

}  // namespace exotwin
