// core/rng against independent references: the C++ standard's mt19937_64 check value, Vigna's
// SplitMix64 outputs, the exact 53-bit uniform transforms, and the sample moments of each normal
// transform.
#include "core/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace exotwin {
namespace {

TEST(Rng, EngineIsTheStandardMt19937_64) {
  // C++ standard [rand.predef]: the 10000th consecutive output of a default-constructed
  // mt19937_64 (seed 5489) is 9981545732273789042.
  Rng rng(5489);
  for (int i = 0; i < 9999; ++i) rng.Bits();
  EXPECT_EQ(rng.Bits(), 9981545732273789042ull);
}

TEST(Rng, MixSeedIsSplitMix64) {
  // splitmix64.c (Vigna) from state 0 gives these outputs; output k is MixSeed(k * golden gamma).
  const uint64_t gamma = 0x9E3779B97F4A7C15ull;
  EXPECT_EQ(MixSeed(0), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(MixSeed(gamma), 0x6E789E6AA1B965F4ull);
  EXPECT_EQ(MixSeed(2 * gamma), 0x06C45D188009454Full);
}

TEST(Rng, UniformTransformsUseTheTop53Bits) {
  Rng a(42), b(42);
  for (int i = 0; i < 1000; ++i) {
    const uint64_t k = b.Bits() >> 11;
    const double u = a.Uniform();
    EXPECT_EQ(u, std::ldexp(static_cast<double>(k), -53));
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
  Rng c(7), d(7);
  for (int i = 0; i < 1000; ++i) {
    const double k = static_cast<double>(d.Bits() >> 11);
    const double u = c.UniformMidpoint();
    EXPECT_EQ(u, (k + 0.5) / 9007199254740992.0);
    EXPECT_GT(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
  Rng e(3), f(3);
  EXPECT_EQ(e.Uniform(-2.0, 6.0), -2.0 + 8.0 * f.Uniform());
  for (int i = 0; i < 1000; ++i) {
    const int j = e.Index(7);
    EXPECT_GE(j, 0);
    EXPECT_LT(j, 7);
    const double s = e.Sign();
    EXPECT_TRUE(s == 1.0 || s == -1.0);
  }
}

// Mean, variance, skewness and excess kurtosis of n draws of `draw`.
template <class Draw>
void ExpectStandardNormal(Draw draw, const char* name) {
  const int n = 400000;
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  std::vector<double> x(n);
  for (double& v : x) {
    v = draw();
    m1 += v;
  }
  m1 /= n;
  for (double v : x) {
    const double d = v - m1;
    m2 += d * d;
    m3 += d * d * d;
    m4 += d * d * d * d;
  }
  m2 /= n;
  m3 /= n;
  m4 /= n;
  // Standard errors at n = 4e5: mean 0.0016, variance 0.0022, skewness 0.0039, kurtosis 0.0077;
  // the bounds are about 5 of them.
  EXPECT_NEAR(m1, 0.0, 0.008) << name;
  EXPECT_NEAR(m2, 1.0, 0.011) << name;
  EXPECT_NEAR(m3 / std::pow(m2, 1.5), 0.0, 0.02) << name;
  EXPECT_NEAR(m4 / (m2 * m2) - 3.0, 0.0, 0.04) << name;
}

TEST(Rng, NormalTransformsHaveStandardNormalMoments) {
  {
    NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> r(11);
    ExpectStandardNormal([&] { return r.Normal(); }, "BoxMuller 1-U");
  }
  {
    NormalRng<NormalBoxMuller<BoxMullerU1::kMidpoint>> r(12);
    ExpectStandardNormal([&] { return r.Normal(); }, "BoxMuller midpoint");
  }
  {
    NormalRng<NormalBoxMullerPair<BoxMullerU1::kMidpoint>> r(13);
    ExpectStandardNormal([&] { return r.Normal(); }, "BoxMuller pair midpoint");
  }
  {
    NormalRng<NormalBoxMullerPair<BoxMullerU1::kNonzeroUniform>> r(14);
    ExpectStandardNormal([&] { return r.Normal(); }, "BoxMuller pair nonzero");
  }
  {
    NormalRng<NormalPolar> r(15);
    ExpectStandardNormal([&] { return r.Normal(); }, "polar");
  }
}

TEST(Rng, BoxMullerFollowsItsFormulaAndDrawOrder) {
  Rng ref(21);
  NormalRng<NormalBoxMullerPair<BoxMullerU1::kOneMinusUniform>> pair(21);
  NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> single(21);
  for (int i = 0; i < 100; ++i) {
    const double u1 = 1.0 - ref.Uniform(), u2 = ref.Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    EXPECT_EQ(pair.Normal(), r * std::cos(2.0 * M_PI * u2));
    EXPECT_EQ(pair.Normal(), r * std::sin(2.0 * M_PI * u2));  // the cached second deviate
    EXPECT_EQ(single.Normal(), r * std::cos(2.0 * M_PI * u2));  // two draws per deviate, sine dropped
  }
}

TEST(Rng, PolarFollowsItsFormulaAndDrawOrder) {
  Rng ref(31);
  NormalRng<NormalPolar> polar(31);
  for (int i = 0; i < 100; ++i) {
    double u, v, s;
    do {
      u = 2.0 * ref.Uniform() - 1.0;
      v = 2.0 * ref.Uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    EXPECT_EQ(polar.Normal(), u * f);
    EXPECT_EQ(polar.Normal(), v * f);
  }
}

}  // namespace
}  // namespace exotwin
