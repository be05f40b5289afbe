// Linear interpolation of a sampled signal (the one home: measured data, sensor delays, column maps).
#pragma once
#include <vector>

namespace exotwin {

// Linear interpolation of (x, y) at xq (x strictly increasing; clamped at the ends).
std::vector<double> Interpolate(const std::vector<double>& x, const std::vector<double>& y,
                                const std::vector<double>& xq);

}  // namespace exotwin
