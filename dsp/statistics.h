// Small sample statistics shared by the analyses (diagnosis, EMG calibration).
#pragma once
#include <cstddef>
#include <vector>

namespace exotwin {

// Pearson correlation of x and y over the samples [a, b) (means removed); 0 if either is constant
// there. Precondition: a <= b <= x.size(), y.size().
double Pearson(const std::vector<double>& x, const std::vector<double>& y, size_t a, size_t b);
// The same over all samples (x.size() == y.size()).
inline double Pearson(const std::vector<double>& x, const std::vector<double>& y) { return Pearson(x, y, 0, x.size()); }

// Integrated autocorrelation length of x[0, n) in samples: 1 + 2 sum of the autocorrelation rho(k)
// over lags k = 1, 2, ... until rho < 0.05 (or k reaches min(n / 4, 2000)); the factor by which
// correlated samples count less than independent ones (n_eff = n / length). 1 for white noise,
// (1 + phi) / (1 - phi) for an AR(1) process; at least 1.
double AutocorrelationLength(const double* x, size_t n);

// The standard normal distribution's upper tail P(Z > z) = erfc(z / sqrt 2) / 2.
double NormalSurvival(double z);
// The standard normal quantile: z with P(Z <= z) = p, for 0 < p < 1 (Acklam's rational approximation,
// relative error < 1.2e-9, refined by one Halley step on erfc); -inf / +inf at p = 0 / 1, NaN outside.
double NormalQuantile(double p);
// The chi-square distribution's upper tail P(X > x) with `dof` > 0 degrees of freedom: the regularized
// upper incomplete gamma function Q(dof / 2, x / 2) (series for x < a + 1, else Lentz's continued
// fraction; Numerical Recipes 3rd ed. 6.2), 1 for x <= 0.
double ChiSquareSurvival(double x, double dof);
// The upper quantile: x with ChiSquareSurvival(x, dof) = alpha, 0 < alpha < 1 (bisection to 1e-12
// relative).
double ChiSquareUpperQuantile(double alpha, double dof);
// Sample autocorrelation of x[0, n) at lags 1 .. m, r(k) = sum (x_i - mean)(x_(i+k) - mean) /
// sum (x_i - mean)^2; zeros where x is constant.
std::vector<double> SampleAutocorrelation(const double* x, size_t n, size_t m);
// Ljung & Box (1978) Q = n (n + 2) sum_(k=1..m) r(k)^2 / (n - k) of x[0, n) (r: SampleAutocorrelation);
// asymptotically chi-square with m degrees of freedom for white noise. Precondition: m < n.
double LjungBoxQ(const double* x, size_t n, size_t m);

// p in [0, 1] of sorted values (linear interpolation between closest ranks); NaN if empty.
double Percentile(const std::vector<double>& sorted, double p);
// Percentile(sorted copy of values, p), the same number, by selection (O(n)): values is reordered.
double PercentileInPlace(std::vector<double>& values, double p);

}  // namespace exotwin
