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

// p in [0, 1] of sorted values (linear interpolation between closest ranks); NaN if empty.
double Percentile(const std::vector<double>& sorted, double p);

}  // namespace exotwin
