// Reproducible standard normal deviates for tests: Box-Muller on raw mt19937_64 bits (no
// std::normal_distribution, whose algorithm differs between standard libraries).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

namespace exotwin::testing {

struct Gauss {
  std::mt19937_64 e{12345};
  double U() { return (static_cast<double>(e() >> 11) + 0.5) * 0x1.0p-53; }  // uniform in (0, 1)
  double operator()() { return std::sqrt(-2 * std::log(U())) * std::cos(2 * M_PI * U()); }
};

}  // namespace exotwin::testing
