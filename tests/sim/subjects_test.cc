// Tests of sim/subjects.h and sim/paper_tables.h: presets and embedded tables against the CSVs in
// data/, and the statistics, realizability and reproducibility of the seeded population.
#include "sim/subjects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "sim/paper_tables.h"
#include "sim/realizability.h"

#include "tests/data_rows.h"

namespace exotwin {
namespace {

double D(const std::string& s) { return std::stod(s); }

void ExpectParams(const LumpedParams& p, const std::vector<std::string>& row, int c,
                  const std::string& what) {
  EXPECT_DOUBLE_EQ(p.J1, D(row[c])) << what;
  EXPECT_DOUBLE_EQ(p.J2, D(row[c + 1])) << what;
  EXPECT_DOUBLE_EQ(p.X1, D(row[c + 2])) << what;
  EXPECT_DOUBLE_EQ(p.X2, D(row[c + 3])) << what;
  EXPECT_DOUBLE_EQ(p.Y1, D(row[c + 4])) << what;
  EXPECT_DOUBLE_EQ(p.Y2, D(row[c + 5])) << what;
}

TEST(Subjects, PresetsMatchTheCsvTables) {
  const auto t2 = ReadDataRows("hwang2015_table2_subjects.csv");
  const auto t3 = ReadDataRows("hwang2015_table3_exo_identified.csv");
  const auto t4 = ReadDataRows("hwang2015_table4_human_identified.csv");
  ASSERT_EQ(t2.size(), 10u);
  ASSERT_EQ(t3.size(), 10u);
  ASSERT_EQ(t4.size(), 10u);
  const auto names = PresetNames();
  ASSERT_EQ(names.size(), 10u);
  for (size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(names[i], "S" + std::to_string(i + 1));
    const Subject s = PresetSubject(t2[i][0]);
    EXPECT_EQ(s.name, t2[i][0]);
    EXPECT_DOUBLE_EQ(s.age, D(t2[i][1]));
    EXPECT_DOUBLE_EQ(s.height, D(t2[i][2]));
    EXPECT_DOUBLE_EQ(s.weight, D(t2[i][3]));
    EXPECT_DOUBLE_EQ(s.L1, D(t2[i][5]));
    EXPECT_DOUBLE_EQ(s.L2, D(t2[i][6]));
    EXPECT_EQ(t3[i][0], s.name);
    EXPECT_EQ(t4[i][0], s.name);
    ExpectParams(s.exo, t3[i], 1, s.name + " exo");
    ExpectParams(s.human, t4[i], 1, s.name + " human");
    const LegParams lp = SubjectLegParams(s);
    EXPECT_EQ(lp.L1, s.L1);
    ASSERT_TRUE(lp.human.has_value());
    EXPECT_EQ(lp.human->X1, s.human.X1);
  }
}

TEST(Subjects, EmbeddedTablesMatchTheCsvs) {
  const auto t2 = ReadDataRows("hwang2015_table2_subjects.csv");
  const auto t4 = ReadDataRows("hwang2015_table4_human_identified.csv");
  const auto t5 = ReadDataRows("hwang2015_table5_rmse.csv");
  ASSERT_EQ(t5.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_DOUBLE_EQ(PaperTable2()[i].bmi, D(t2[i][4]));
    const Table4Row& r = PaperTable4()[i];
    const double dl[4] = {r.deleva.J1, r.deleva.J2, r.deleva.X1, r.deleva.X2};
    const double dp[4] = {r.dempster.J1, r.dempster.J2, r.dempster.X1, r.dempster.X2};
    for (int k = 0; k < 4; ++k) {
      EXPECT_DOUBLE_EQ(dl[k], D(t4[i][7 + k]));
      EXPECT_DOUBLE_EQ(dp[k], D(t4[i][11 + k]));
    }
    const Table5Row& q = PaperTable5()[i];
    const double rmse[6] = {q.hip_identified, q.hip_deleva, q.hip_dempster,
                            q.knee_identified, q.knee_deleva, q.knee_dempster};
    EXPECT_EQ(t5[i][0], q.subject);
    for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(rmse[k], D(t5[i][1 + k]));
  }
}

TEST(Subjects, UnknownPresetThrowsListingValidNames) {
  try {
    PresetSubject("S11");
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("S11"), std::string::npos) << msg;
    EXPECT_NE(msg.find("S1 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("S10"), std::string::npos) << msg;
  }
  EXPECT_THROW(PresetSubject("s1"), InputError);
  EXPECT_THROW(DrawSubject(1, -1), InputError);
}

struct Stats {
  double mean[6], sd[6];
};

Stats HumanStats(const std::vector<Subject>& v, bool exo) {
  Stats s{};
  const double n = static_cast<double>(v.size());
  for (int k = 0; k < 6; ++k) {
    double sum = 0, sum2 = 0;
    for (const Subject& x : v) {
      const LumpedParams& p = exo ? x.exo : x.human;
      const double f[6] = {p.J1, p.J2, p.X1, p.X2, p.Y1, p.Y2};
      sum += f[k];
      sum2 += f[k] * f[k];
    }
    s.mean[k] = sum / n;
    s.sd[k] = std::sqrt((sum2 - sum * sum / n) / (n - 1));
  }
  return s;
}

std::vector<Subject> Draw1000(uint64_t seed) {
  std::vector<Subject> v;
  for (int i = 0; i < 1000; ++i) v.push_back(DrawSubject(seed, i));
  return v;
}

TEST(Subjects, PopulationReproducesTable4Spread) {
  // Table 4 printed Mean / SD rows (identified), J_H1, J_H2, X_H1, X_H2, Y_H1, Y_H2.
  const double mean[6] = {1.43, 0.41, 3.89, 1.14, -0.31, 0.35};
  const double sd[6] = {0.15, 0.05, 0.44, 0.15, 0.14, 0.07};
  const char* names[6] = {"J_H1", "J_H2", "X_H1", "X_H2", "Y_H1", "Y_H2"};
  for (uint64_t seed : {1ull, 2024ull}) {
    const auto v = Draw1000(seed);
    const Stats s = HumanStats(v, false);
    for (int k = 0; k < 6; ++k) {
      std::printf("seed %llu %s mean %+.4f (paper %+.2f) sd %.4f (paper %.2f)\n",
                  static_cast<unsigned long long>(seed), names[k], s.mean[k], mean[k], s.sd[k],
                  sd[k]);
      EXPECT_NEAR(s.mean[k], mean[k], 0.10 * std::abs(mean[k])) << names[k];
      EXPECT_NEAR(s.sd[k], sd[k], 0.10 * sd[k]) << names[k];
    }
  }
}

TEST(Subjects, PopulationExoFollowsTable3) {
  const double mean[6] = {3.01, 0.74, 3.85, 1.73, 0.14, 0.18};
  const double sd[6] = {0.13, 0.03, 0.10, 0.04, 0.02, 0.01};
  const Stats s = HumanStats(Draw1000(7), true);
  for (int k = 0; k < 6; ++k) {
    std::printf("exo %d mean %.4f (paper %.2f) sd %.4f (paper %.2f)\n", k, s.mean[k], mean[k],
                s.sd[k], sd[k]);
    EXPECT_NEAR(s.mean[k], mean[k], 0.05 * mean[k]) << k;
    // Printed SDs have one significant digit (0.01, 0.02): allow the rounding half-step + 10 %.
    EXPECT_NEAR(s.sd[k], sd[k], 0.1 * sd[k] + 0.005) << k;
  }
}

TEST(Subjects, PopulationIsRealizableAndPlausible) {
  for (const Subject& s : Draw1000(3)) {
    std::string why;
    EXPECT_TRUE(IsRealizable(s.human, s.L1, &why)) << s.name << ": " << why;
    EXPECT_TRUE(IsRealizable(s.exo, s.L1, &why)) << s.name << ": " << why;
    EXPECT_GT(s.weight, 30);
    EXPECT_LT(s.weight, 120);
    EXPECT_GT(s.L1, 0.3);
    EXPECT_LT(s.L1, 0.55);
    EXPECT_GT(s.L2, 0.4);
    EXPECT_LT(s.L2, 0.65);
    EXPECT_GT(s.height, 1.4);
    EXPECT_LT(s.height, 2.1);
  }
}

bool SameBits(const Subject& a, const Subject& b) {
  const double x[] = {a.age, a.height, a.weight, a.L1, a.L2, a.human.J1, a.human.J2, a.human.X1,
                      a.human.X2, a.human.Y1, a.human.Y2, a.exo.J1, a.exo.J2, a.exo.X1, a.exo.X2,
                      a.exo.Y1, a.exo.Y2};
  const double y[] = {b.age, b.height, b.weight, b.L1, b.L2, b.human.J1, b.human.J2, b.human.X1,
                      b.human.X2, b.human.Y1, b.human.Y2, b.exo.J1, b.exo.J2, b.exo.X1, b.exo.X2,
                      b.exo.Y1, b.exo.Y2};
  return std::memcmp(x, y, sizeof(x)) == 0 && a.name == b.name;
}

TEST(Subjects, SameSeedSameBitsDifferentSeedsDiffer) {
  for (int i : {0, 1, 17, 999}) {
    EXPECT_TRUE(SameBits(DrawSubject(42, i), DrawSubject(42, i))) << i;
    EXPECT_FALSE(SameBits(DrawSubject(42, i), DrawSubject(43, i))) << i;
    EXPECT_NE(DrawSubject(42, i).human.X1, DrawSubject(43, i).human.X1) << i;
  }
  EXPECT_NE(DrawSubject(42, 0).human.J1, DrawSubject(42, 1).human.J1);
  // Order independence: index 5 does not depend on whether 0..4 were drawn before.
  const Subject late = DrawSubject(9, 5);
  EXPECT_TRUE(SameBits(late, Draw1000(9)[5]));
}

}  // namespace
}  // namespace exotwin
