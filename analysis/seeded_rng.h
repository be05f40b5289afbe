// Portable seeded random numbers: std::mt19937_64 raw bits turned into uniform and normal deviates
// by our own formulas, so the same seed gives the same bits with every standard library (the std::
// distributions are implementation-defined).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

namespace exotwin {

class SeededRng {
 public:
  explicit SeededRng(uint64_t seed) : gen_(seed) {}
  // Uniform in [0, 1): the top 53 bits of one draw.
  double Uniform() { return static_cast<double>(gen_() >> 11) * (1.0 / 9007199254740992.0); }
  // Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Integer in [0, n), n >= 1.
  int Index(int n) { return static_cast<int>(Uniform() * n) % n; }
  // +1 or -1 with equal probability.
  double Sign() { return Uniform() < 0.5 ? -1.0 : 1.0; }
  // Standard normal deviate (Box-Muller, both uniforms from this generator; no cached pair).
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 gen_;
};

}  // namespace exotwin
