// identification/table5.h: the RMS error of HJ15 eq. 22 against the closed form, the three parameter sets of
// Table 5, and the side-by-side text.
#include "identification/table5.h"

#include <gtest/gtest.h>

#include <cmath>

#include "identification/identification_data.h"
#include "model/leg_dynamics.h"
#include "sim/anthropometry.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

// A smooth 2 s "gait" whose sensor column is exactly -tau_R of `p` plus `offset` (N m) on both joints.
MeasuredData Synthetic(const LegParams& p, double offset) {
  CsvTable tab;
  tab.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  tab.columns.assign(5, {});
  for (int i = 0; i < 4000; ++i) {
    const double t = i * 1e-3, w = M_PI;
    const Vec2 q(0.3 * std::sin(w * t), -0.6 + 0.4 * std::sin(w * t)), qd(0.3 * w * std::cos(w * t), 0.4 * w * std::cos(w * t)),
        qdd(-0.3 * w * w * std::sin(w * t), -0.4 * w * w * std::sin(w * t));
    const Vec2 tau = ActuatorTorque(p, q, qd, qdd);
    tab.columns[0].push_back(t);
    tab.columns[1].push_back(q[0]);
    tab.columns[2].push_back(q[1]);
    tab.columns[3].push_back(-tau[0] + offset);
    tab.columns[4].push_back(-tau[1] + offset);
    tab.line_of_row.push_back(i + 2);
  }
  return MakeMeasuredData(std::move(tab), "synthetic");
}

TEST(Table5, RmseIsTheOffsetWhenTheModelIsExact) {
  LegParams p = SubjectLegParams(PresetSubject("S1"));
  p.passive = PassiveModel::kRiener1999;
  const auto r0 = GaitTorqueRmse(Synthetic(p, 0.0), p, 0.5, 3.5);
  EXPECT_LT(r0.first, 0.05);  // only the 20 Hz derivative filter's error
  EXPECT_LT(r0.second, 0.05);
  const auto r1 = GaitTorqueRmse(Synthetic(p, 1.5), p, 0.5, 3.5);
  EXPECT_NEAR(r1.first, 1.5, 0.05);
  EXPECT_NEAR(r1.second, 1.5, 0.05);
  EXPECT_THROW(GaitTorqueRmse(Synthetic(p, 0.0), p, 100.0, 200.0), std::exception);
}

TEST(Table5, ParameterSetsKeepTheExoAndSwapTheHuman) {
  const Subject s = PresetSubject("S2");
  const LegParams id = SubjectLegParams(s);
  const auto sets = Table5ParameterSets(id, s.weight, s.L2);
  ASSERT_EQ(sets.size(), 3u);
  for (const LegParams& p : sets) {
    EXPECT_EQ(p.exo.J1, id.exo.J1);
    EXPECT_EQ(p.passive, PassiveModel::kRiener1999);
  }
  EXPECT_EQ(sets[0].human->J2, id.human->J2);
  const LumpedParams dl = Table4AnthropometricLumped(AnthropometricModel::kDeLeva, s.weight, s.L1, s.L2);
  EXPECT_DOUBLE_EQ(sets[1].human->X1, dl.X1);
  EXPECT_EQ(sets[1].human->Y1, 0.0);
}

TEST(Table5, MarkdownAndCsvCarryTwinAndPaper) {
  Table5Entry e;
  e.subject = "S1";
  e.truth = e.identified = SubjectLegParams(PresetSubject("S1"));
  e.hip = {2.0, 4.0, 5.0};
  e.knee = {1.0, 2.0, 3.0};
  const std::string md = Table5Markdown({e}, "# header");
  EXPECT_NE(md.find("| S1 | 2.00 / 4.00 / 5.00 | 2.10 / 3.80 / 4.90 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| hip | 2.00 / 2.50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Table 4"), std::string::npos);
  const std::string csv = Table5Csv({e});
  EXPECT_NE(csv.find("S1,2.0000,4.0000,5.0000,1.0000,2.0000,3.0000,2.1000,3.8000,4.9000,1.2000,2.5000,3.8000"),
            std::string::npos) << csv;
}

}  // namespace
}  // namespace exotwin
