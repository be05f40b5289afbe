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

// p in [0, 1] of sorted values (linear interpolation between closest ranks); NaN if empty.
double Percentile(const std::vector<double>& sorted, double p);
// Percentile(sorted copy of values, p), the same number, by selection (O(n)): values is reordered.
double PercentileInPlace(std::vector<double>& values, double p);

}  // namespace exotwin
