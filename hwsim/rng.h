// Portable seeded random numbers for the device models: std::mt19937_64 raw bits turned into uniform
// and normal variates by our own code (std:: distributions differ between standard libraries; the
// same seed must give the same bits everywhere).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

namespace exotwin::hwsim {

class Rng {
 public:
  explicit Rng(uint64_t seed) : gen_(seed) {}
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(gen_() >> 11) * (1.0 / 9007199254740992.0); }
  // Standard normal (Box-Muller, caches the second variate).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = Uniform();
    while (u1 <= 0.0) u1 = Uniform();
    const double u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 gen_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace exotwin::hwsim
