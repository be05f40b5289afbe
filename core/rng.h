// Seeded random numbers that give the same bits on every machine and standard library.
//
// The engine is std::mt19937_64 (fully specified by the C++ standard). Its raw 64-bit draws are turned
// into uniform and normal deviates by the transforms below, not by the std:: distributions (those are
// implementation-defined). Every random stream of the project uses one normal transform with a fixed
// draw order, so the transforms are named by algorithm and are not interchangeable: changing the
// transform of a stream changes its numbers.
//
//   Rng                          engine + uniform transforms (53-bit uniforms, ranges, index, sign)
//   NormalBoxMuller<U1>          Box & Muller (1958), cosine branch only: one deviate per 2 uniforms
//   NormalBoxMullerPair<U1>      Box & Muller (1958), both branches: cosine, then the cached sine
//   NormalPolar                  Marsaglia & Bray (1964) polar method, both deviates (second cached)
//   NormalRng<Transform>         an Rng whose Normal() is the given transform
//   MixSeed                      SplitMix64 finaliser for derived seeds
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

namespace exotwin {

// SplitMix64 (Steele, Lea & Flood 2014; Vigna's splitmix64.c): one step of the generator from state x,
// i.e. the finaliser of x + 0x9E3779B97F4A7C15. Decorrelates derived seeds (e.g. seed ^ stream id).
uint64_t MixSeed(uint64_t x);

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  // One raw 64-bit draw of the engine.
  uint64_t Bits() { return engine_(); }
  // Uniform in [0, 1): k 2^-53, k the top 53 bits of one draw.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Uniform in (0, 1): (k + 1/2) 2^-53, k the top 53 bits of one draw (never 0, never 1).
  double UniformMidpoint() { return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53; }
  // Uniform in [lo, hi): lo + (hi - lo) Uniform().
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Integer in [0, n) from one draw; precondition n >= 1.
  int Index(int n) { return static_cast<int>(Uniform() * n) % n; }
  // +1 or -1 with equal probability, from one draw.
  double Sign() { return Uniform() < 0.5 ? -1.0 : 1.0; }

 private:
  std::mt19937_64 engine_;
};

// How Box-Muller draws its radius uniform u1 in (0, 1] (r = sqrt(-2 ln u1)); part of the stream.
enum class BoxMullerU1 {
  kOneMinusUniform,  // 1 - Uniform(): one draw
  kMidpoint,         // UniformMidpoint(): one draw
  kNonzeroUniform,   // Uniform(), drawn again while it is 0
};

namespace rng_detail {
template <BoxMullerU1 U1>
double RadiusUniform(Rng& rng) {
  if constexpr (U1 == BoxMullerU1::kOneMinusUniform) {
    return 1.0 - rng.Uniform();
  } else if constexpr (U1 == BoxMullerU1::kMidpoint) {
    return rng.UniformMidpoint();
  } else {
    double u1 = rng.Uniform();
    while (u1 <= 0.0) u1 = rng.Uniform();
    return u1;
  }
}
}  // namespace rng_detail

// Standard normal, Box & Muller (1958): z = sqrt(-2 ln u1) cos(2 pi u2), u1 drawn as U1, then
// u2 = Uniform(). The sine deviate of the pair is discarded; stateless.
template <BoxMullerU1 U1>
struct NormalBoxMuller {
  double operator()(Rng& rng) const {
    const double u1 = rng_detail::RadiusUniform<U1>(rng);
    const double u2 = rng.Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
};

// Standard normals, Box & Muller (1958), both deviates of each pair: r cos(2 pi u2) on the first
// call, the cached r sin(2 pi u2) on the next (u1 drawn as U1, then u2 = Uniform()).
template <BoxMullerU1 U1>
class NormalBoxMullerPair {
 public:
  double operator()(Rng& rng) {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = rng_detail::RadiusUniform<U1>(rng);
    const double u2 = rng.Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

 private:
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Standard normals, Marsaglia & Bray (1964) polar method: u, v = 2 Uniform() - 1 (u first) until
// 0 < s = u^2 + v^2 < 1; returns u f, then the cached v f, f = sqrt(-2 ln s / s).
class NormalPolar {
 public:
  double operator()(Rng& rng);

 private:
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// An Rng whose Normal() draws with `Transform` from the same engine as its uniforms.
template <class Transform>
class NormalRng : public Rng {
 public:
  explicit NormalRng(uint64_t seed) : Rng(seed) {}
  double Normal() { return normal_(*this); }

 private:
  Transform normal_;
};

}  // namespace exotwin
