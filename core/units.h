// Angle unit conversions. SI (rad) everywhere in files and APIs; degrees only in human-facing text
// and where a source (paper, table) gives them. Both constants are the double nearest to the exact
// value: x * kRadPerDeg is x * (pi / 180), rounded once after the product (not x * pi / 180).
#pragma once
#include <cmath>

namespace exotwin {

constexpr double kRadPerDeg = M_PI / 180.0;  // rad per degree
constexpr double kDegPerRad = 180.0 / M_PI;  // degrees per rad

}  // namespace exotwin
