// Tests of sim/realizability.h: the feasibility condition, checked constructively.
#include "sim/realizability.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "sim/subjects.h"

namespace exotwin {
namespace {

LumpedParams S1Human() {
  LumpedParams p;  // Table 4, S1 identified
  p.J1 = 1.69;
  p.J2 = 0.37;
  p.X1 = 4.54;
  p.X2 = 1.20;
  p.Y1 = -0.16;
  p.Y2 = 0.42;
  return p;
}

// Builds one realization by hand (m2 in the middle of its window, m1 twice its bound) and checks
// it is physical and lumps back to p: the constructive side of the condition.
void ExpectConstructive(const LumpedParams& p, double L1) {
  const double lo2 = (p.X2 * p.X2 + p.Y2 * p.Y2) / p.J2, hi2 = (p.J1 - p.J2) / (L1 * L1);
  const double m2 = 0.5 * (lo2 + hi2);
  const double a2 = p.X2 / m2, b2 = p.Y2 / m2, Iz2 = p.J2 - m2 * (a2 * a2 + b2 * b2);
  const double den = p.J1 - p.J2 - m2 * L1 * L1;
  const double m1 = 2.0 * ((p.X1 - m2 * L1) * (p.X1 - m2 * L1) + p.Y1 * p.Y1) / den + 1e-3;
  const double a1 = (p.X1 - m2 * L1) / m1, b1 = p.Y1 / m1;
  const double Iz1 = den - m1 * (a1 * a1 + b1 * b1);
  EXPECT_GT(m2, 0);
  EXPECT_GT(m1, 0);
  EXPECT_GT(Iz2, 0);
  EXPECT_GT(Iz1, 0);
  // HJ15 eq. 4
  EXPECT_NEAR(Iz1 + Iz2 + m1 * (a1 * a1 + b1 * b1) + m2 * (a2 * a2 + b2 * b2) + m2 * L1 * L1, p.J1,
              1e-9);
  EXPECT_NEAR(m1 * a1 + m2 * L1, p.X1, 1e-9);
  EXPECT_NEAR(m1 * b1, p.Y1, 1e-12);
}

TEST(Realizability, PaperSubjectsAreRealizableExceptS3) {
  for (const auto& name : PresetNames()) {
    const Subject s = PresetSubject(name);
    std::string why = "stale";
    EXPECT_TRUE(IsRealizable(s.exo, s.L1, &why)) << name << " exo: " << why;
    ExpectConstructive(s.exo, s.L1);
    if (name == "S3") continue;
    EXPECT_TRUE(IsRealizable(s.human, s.L1, &why)) << name << ": " << why;
    EXPECT_TRUE(why.empty());
    ExpectConstructive(s.human, s.L1);
  }
}

TEST(Realizability, PaperS3HumanIsNotRealizable) {
  // Table 4, S3: J1 1.50, J2 0.40, X2 1.50, Y2 0.42 at L1 = 0.43 m:
  // (X2^2 + Y2^2)/J2 = 2.4264/0.40 = 6.066 kg > (J1 - J2)/L1^2 = 1.10/0.1849 = 5.949 kg.
  const Subject s = PresetSubject("S3");
  std::string why;
  EXPECT_FALSE(IsRealizable(s.human, s.L1, &why));
  EXPECT_NE(why.find("6.066"), std::string::npos) << why;
  EXPECT_NE(why.find("5.949"), std::string::npos) << why;
}

TEST(Realizability, RejectsNonPositiveJ2) {
  LumpedParams p = S1Human();
  std::string why;
  p.J2 = 0.0;
  EXPECT_FALSE(IsRealizable(p, 0.41, &why));
  EXPECT_NE(why.find("J2"), std::string::npos) << why;
  p.J2 = -0.1;
  EXPECT_FALSE(IsRealizable(p, 0.41, nullptr));
}

TEST(Realizability, BoundaryOnJ1IsSharp) {
  LumpedParams p = S1Human();
  const double L1 = 0.41;
  // J1 at the boundary: (J1 - J2)/L1^2 = (X2^2 + Y2^2)/J2.
  const double J1_min = p.J2 + L1 * L1 * (p.X2 * p.X2 + p.Y2 * p.Y2) / p.J2;  // 1.0071
  std::string why;
  p.J1 = J1_min * 0.99;
  EXPECT_FALSE(IsRealizable(p, L1, &why));
  EXPECT_NE(why.find("J1 too small"), std::string::npos) << why;
  p.J1 = J1_min;
  EXPECT_FALSE(IsRealizable(p, L1, nullptr));
  p.J1 = J1_min * 1.01;
  EXPECT_TRUE(IsRealizable(p, L1, nullptr));
  ExpectConstructive(p, L1);
  // J1 < J2 is never realizable.
  p.J1 = 0.3;
  EXPECT_FALSE(IsRealizable(p, L1, nullptr));
}

TEST(Realizability, RejectsBadNumbersAndLength) {
  LumpedParams p = S1Human();
  EXPECT_FALSE(IsRealizable(p, 0.0, nullptr));
  EXPECT_FALSE(IsRealizable(p, -0.41, nullptr));
  p.X1 = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(IsRealizable(p, 0.41, nullptr));
  p = S1Human();
  p.Y2 = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(IsRealizable(p, 0.41, nullptr));
}

TEST(Realizability, EveryPhysicalLegIsRealizable) {
  // Random positive masses and inertias, any offsets: HJ15 eq. 4 of them must be accepted.
  std::mt19937_64 g(5);
  auto u = [&g](double lo, double hi) { return lo + (hi - lo) * ((g() >> 11) * 0x1.0p-53); };
  for (int i = 0; i < 1000; ++i) {
    const double L1 = u(0.2, 0.6), m1 = u(0.1, 15), m2 = u(0.1, 8);
    const double a1 = u(-0.2, 0.5), b1 = u(-0.1, 0.1), a2 = u(-0.2, 0.6), b2 = u(-0.1, 0.1);
    const double Iz1 = u(1e-4, 0.3), Iz2 = u(1e-4, 0.2);
    LumpedParams p;
    p.J2 = Iz2 + m2 * (a2 * a2 + b2 * b2);
    p.J1 = Iz1 + m1 * (a1 * a1 + b1 * b1) + p.J2 + m2 * L1 * L1;
    p.X1 = m1 * a1 + m2 * L1;
    p.X2 = m2 * a2;
    p.Y1 = m1 * b1;
    p.Y2 = m2 * b2;
    std::string why;
    EXPECT_TRUE(IsRealizable(p, L1, &why)) << why;
  }
}

}  // namespace
}  // namespace exotwin
