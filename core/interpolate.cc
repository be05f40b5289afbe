#include "core/interpolate.h"

#include <cstddef>

namespace exotwin {

std::vector<double> Interpolate(const std::vector<double>& x, const std::vector<double>& y,
                                const std::vector<double>& xq) {
  std::vector<double> out(xq.size());
  size_t j = 0;
  for (size_t i = 0; i < xq.size(); ++i) {
    const double v = xq[i];
    if (v <= x.front()) { out[i] = y.front(); continue; }
    if (v >= x.back()) { out[i] = y.back(); continue; }
    if (j > 0 && x[j] > v) j = 0;
    while (j + 1 < x.size() && x[j + 1] < v) ++j;
    const double w = (v - x[j]) / (x[j + 1] - x[j]);
    out[i] = y[j] + w * (y[j + 1] - y[j]);
  }
  return out;
}

}  // namespace exotwin
