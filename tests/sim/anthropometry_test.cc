// Tests of sim/anthropometry.h: HJ15 eq. 11 by hand, HJ15 eq. 4 by hand, and how close the adopted rule
// lands on Table 4's printed anthropometric columns (read from data/, not from sim/paper_tables).
#include "sim/anthropometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"

#include "tests/data_rows.h"

namespace exotwin {
namespace {

TEST(Anthropometry, Eq11DeLevaTable1ByHandForS1) {
  // S1: W = 75.2 kg, L1 = 0.41 m, L2 = 0.53 m; Table 1 De Leva: thigh 14.2/45.5/32.9,
  // shank 4.3/40.5/25.5, foot 1.4 % as a point mass at L2.
  const LegBsip b = AnthropometricBsip(AnthropometricModel::kDeLeva, 75.2, 0.41, 0.53);
  EXPECT_NEAR(b.thigh.mass, 10.6784, 1e-12);      // 75.2 * 0.142
  EXPECT_NEAR(b.thigh.a, 0.18655, 1e-12);         // 0.41 * 0.455
  EXPECT_NEAR(b.thigh.Iz, 0.1942968207, 1e-9);    // 10.6784 * (0.41 * 0.329)^2
  EXPECT_EQ(b.thigh.b, 0.0);
  EXPECT_NEAR(b.lower_leg.mass, 4.2864, 1e-12);   // 75.2 * (0.043 + 0.014)
  // (3.2336 * 0.53 * 0.405 + 1.0528 * 0.53) / 4.2864
  EXPECT_NEAR(b.lower_leg.a, 0.2921043860, 1e-9);
  // J2 = 3.2336 (0.53 * 0.255)^2 + 3.2336 (0.21465)^2 + 1.0528 * 0.53^2 = 0.5037818129; Iz = J2 - m a^2
  EXPECT_NEAR(b.lower_leg.Iz, 0.5037818129 - 4.2864 * 0.2921043860 * 0.2921043860, 1e-8);
  EXPECT_EQ(b.L1, 0.41);
  const LumpedParams p = LumpFromBsip(b);
  EXPECT_NEAR(p.J2, 0.5037818129, 1e-9);
  EXPECT_NEAR(p.X1, 10.6784 * 0.18655 + 4.2864 * 0.41, 1e-9);  // 3.74947952
  EXPECT_NEAR(p.X2, 1.25207624, 1e-8);
}

TEST(Anthropometry, LumpFromBsipMatchesHandComputation) {
  LegBsip b;
  b.L1 = 0.4;
  b.thigh = {8.0, 0.2, 0.01, 0.1};
  b.lower_leg = {4.0, 0.25, -0.02, 0.05};
  const LumpedParams p = LumpFromBsip(b);
  // J2 = 0.05 + 4 (0.0625 + 0.0004); J1 = 0.1 + 0.05 + 8 (0.04 + 0.0001) + 4 (0.0625 + 0.0004) + 4 0.16
  EXPECT_NEAR(p.J2, 0.3016, 1e-12);
  EXPECT_NEAR(p.J1, 1.3624, 1e-12);
  EXPECT_NEAR(p.X1, 3.2, 1e-12);  // 8 0.2 + 4 0.4
  EXPECT_NEAR(p.X2, 1.0, 1e-12);
  EXPECT_NEAR(p.Y1, 0.08, 1e-12);
  EXPECT_NEAR(p.Y2, -0.08, 1e-12);
  EXPECT_EQ(p.m1, 8.0);
  EXPECT_EQ(p.m2, 4.0);
}

TEST(Anthropometry, Table4RuleDempsterByHandForS1) {
  // Winter's Dempster "Foot leg" row: 6.1 %, CM 60.6 %, RG 41.6 % of L2; thigh 10.0/43.3/32.3 %.
  const LumpedParams p =
      Table4AnthropometricLumped(AnthropometricModel::kDempster, 75.2, 0.41, 0.53);
  const double m2 = 75.2 * 0.061, m1 = 75.2 * 0.100;
  const double J2 = m2 * 0.53 * 0.53 * (0.606 * 0.606 + 0.416 * 0.416);  // 0.69619
  EXPECT_NEAR(p.J2, J2, 1e-9);
  EXPECT_NEAR(p.J1, m1 * 0.41 * 0.41 * (0.433 * 0.433 + 0.323 * 0.323) + J2 + m2 * 0.41 * 0.41, 1e-9);
  EXPECT_NEAR(p.X1, m1 * 0.433 * 0.41 + m2 * 0.41, 1e-9);
  EXPECT_NEAR(p.X2, m2 * 0.606 * 0.53, 1e-9);
  EXPECT_EQ(p.Y1, 0.0);
  EXPECT_EQ(p.Y2, 0.0);
}

// Mean relative error (computed / printed - 1) of J_H1, J_H2, X_H1, X_H2 over S1..S10.
std::vector<double> MeanRelErrors(bool table4_rule, AnthropometricModel m, int first_col) {
  const auto t2 = ReadDataRows("hwang2015_table2_subjects.csv");
  const auto t4 = ReadDataRows("hwang2015_table4_human_identified.csv");
  EXPECT_EQ(t2.size(), 10u);
  EXPECT_EQ(t4.size(), 10u);
  std::vector<double> err(4, 0.0);
  for (size_t i = 0; i < t2.size(); ++i) {
    const double W = std::stod(t2[i][3]), L1 = std::stod(t2[i][5]), L2 = std::stod(t2[i][6]);
    const LumpedParams p =
        table4_rule ? Table4AnthropometricLumped(m, W, L1, L2)
                    : LumpFromBsip(AnthropometricBsip(m, W, L1, L2));
    const double c[4] = {p.J1, p.J2, p.X1, p.X2};
    for (int k = 0; k < 4; ++k) err[k] += (c[k] / std::stod(t4[i][first_col + k]) - 1.0) / 10.0;
  }
  std::printf("%s %-8s  J_H1 %+6.1f %%  J_H2 %+6.1f %%  X_H1 %+6.1f %%  X_H2 %+6.1f %%\n",
              table4_rule ? "adopted rule" : "Table 1     ", AnthropometricModelName(m),
              100 * err[0], 100 * err[1], 100 * err[2], 100 * err[3]);
  return err;
}

TEST(Anthropometry, AdoptedRuleLandsWhereDocumented) {
  // The numbers recorded in sim/anthropometry.cc (percent), to 0.3 percentage points.
  const double deleva[4] = {16.2, 19.4, 0.0, 8.2};
  const double dempster[4] = {7.5, -0.1, 0.2, 5.7};
  const auto e_dl = MeanRelErrors(true, AnthropometricModel::kDeLeva, 7);
  const auto e_dp = MeanRelErrors(true, AnthropometricModel::kDempster, 11);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(100 * e_dl[k], deleva[k], 0.3) << "De Leva column " << k;
    EXPECT_NEAR(100 * e_dp[k], dempster[k], 0.3) << "Dempster column " << k;
  }
  // The adopted rule is closer to the printed columns than Table 1 as printed.
  const auto t1_dl = MeanRelErrors(false, AnthropometricModel::kDeLeva, 7);
  const auto t1_dp = MeanRelErrors(false, AnthropometricModel::kDempster, 11);
  double adopted = 0, table1 = 0;
  for (int k = 0; k < 4; ++k) {
    adopted += std::abs(e_dl[k]) + std::abs(e_dp[k]);
    table1 += std::abs(t1_dl[k]) + std::abs(t1_dp[k]);
  }
  EXPECT_LT(adopted, table1);
  // X_H1 (the thigh) is reproduced for both models.
  EXPECT_LT(std::abs(e_dl[2]), 0.01);
  EXPECT_LT(std::abs(e_dp[2]), 0.01);
}

TEST(Anthropometry, RejectsClauserAndBadInput) {
  EXPECT_THROW(AnthropometricBsip(AnthropometricModel::kClauser, 70, 0.4, 0.5), InputError);
  EXPECT_THROW(Table4RuleBsip(AnthropometricModel::kClauser, 70, 0.4, 0.5), InputError);
  EXPECT_THROW(AnthropometricBsip(AnthropometricModel::kDeLeva, 0, 0.4, 0.5), InputError);
  EXPECT_THROW(AnthropometricBsip(AnthropometricModel::kDeLeva, 70, -0.4, 0.5), InputError);
  EXPECT_THROW(AnthropometricBsip(AnthropometricModel::kDempster, 70, 0.4, NAN), InputError);
  try {
    AnthropometricBsip(AnthropometricModel::kDeLeva, 70, 0.4, 0.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("L2"), std::string::npos) << e.what();
  }
}

TEST(Anthropometry, BsipIsPhysical) {
  for (auto m : {AnthropometricModel::kDeLeva, AnthropometricModel::kDempster}) {
    for (const LegBsip& b : {AnthropometricBsip(m, 70, 0.4, 0.5), Table4RuleBsip(m, 70, 0.4, 0.5)}) {
      EXPECT_GT(b.thigh.mass, 0);
      EXPECT_GT(b.thigh.Iz, 0);
      EXPECT_GT(b.lower_leg.mass, 0);
      EXPECT_GT(b.lower_leg.Iz, 0);
      EXPECT_GT(b.lower_leg.a, 0);
      EXPECT_LT(b.lower_leg.a, 0.5);
    }
  }
}

}  // namespace
}  // namespace exotwin
