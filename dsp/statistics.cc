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

double NormalSurvival(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

double NormalQuantile(double p) {
  if (!(p >= 0 && p <= 1)) return std::nan("");
  if (p == 0) return -INFINITY;
  if (p == 1) return INFINITY;
  // Acklam (2003): rational approximations on the central region and the two tails.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01,  -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double lo = 0.02425;
  double x;
  if (p < lo) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p <= 1 - lo) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  } else {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  // One Halley step on Phi(x) - p, Phi(x) = erfc(-x / sqrt 2) / 2.
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2 * M_PI) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

double ChiSquareSurvival(double x, double dof) {
  if (!(x > 0)) return 1.0;
  const double a = dof / 2, z = x / 2;
  const double log_front = -z + a * std::log(z) - std::lgamma(a);
  if (z < a + 1) {  // P(a, z) by its series, Q = 1 - P
    double term = 1 / a, sum = term;
    for (int k = 1; k < 10000; ++k) {
      term *= z / (a + k);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return std::max(0.0, 1 - sum * std::exp(log_front));
  }
  // Q(a, z) by the continued fraction, modified Lentz.
  const double tiny = 1e-300;
  double bq = z + 1 - a, cq = 1 / tiny, dq = 1 / bq, h = dq;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    bq += 2;
    dq = an * dq + bq;
    if (std::abs(dq) < tiny) dq = tiny;
    cq = bq + an / cq;
    if (std::abs(cq) < tiny) cq = tiny;
    dq = 1 / dq;
    const double del = dq * cq;
    h *= del;
    if (std::abs(del - 1) < 1e-16) break;
  }
  return std::exp(log_front) * h;
}

double ChiSquareUpperQuantile(double alpha, double dof) {
  double lo = 0, hi = std::max(1.0, dof);
  while (ChiSquareSurvival(hi, dof) > alpha) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareSurvival(mid, dof) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<double> SampleAutocorrelation(const double* x, size_t n, size_t m) {
  std::vector<double> r(m, 0.0);
  if (n == 0) return r;
  double mean = 0;
  for (size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  double v = 0;
  for (size_t i = 0; i < n; ++i) v += (x[i] - mean) * (x[i] - mean);
  if (!(v > 0)) return r;
  for (size_t k = 1; k <= m && k < n; ++k) {
    double c = 0;
    for (size_t i = 0; i + k < n; ++i) c += (x[i] - mean) * (x[i + k] - mean);
    r[k - 1] = c / v;
  }
  return r;
}

double LjungBoxQ(const double* x, size_t n, size_t m) {
  const std::vector<double> r = SampleAutocorrelation(x, n, m);
  const double N = static_cast<double>(n);
  double q = 0;
  for (size_t k = 1; k <= m && k < n; ++k) q += r[k - 1] * r[k - 1] / (N - static_cast<double>(k));
  return N * (N + 2) * q;
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
