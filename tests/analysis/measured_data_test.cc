// Measured-data angles: a record may turn a joint through several revolutions (up to the sanity
// bound kMaxRecordedAngle); a human joint's range (2 pi) is a separate check naming file, line, column.
#include "analysis/measured_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "core/error.h"

namespace exotwin {
namespace {

// 30 rows at 1 kHz, data row i on line i + 2; q_knee of row `row` set to `q`.
CsvTable Table(int row, double q) {
  CsvTable t;
  t.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  t.columns.assign(5, {});
  for (int i = 0; i < 30; ++i) {
    const double v[5] = {1e-3 * i, 0.1, i == row ? q : -0.5, 1.0, 2.0};
    for (int c = 0; c < 5; ++c) t.columns[c].push_back(v[c]);
    t.line_of_row.push_back(i + 2);
  }
  return t;
}

TEST(MeasuredAngles, ARecordMayTurnThroughSeveralRevolutions) {
  const MeasuredData d = MeasuredFromTable(Table(7, 11.0), "rig.csv");
  EXPECT_DOUBLE_EQ(d.q_knee[7], 11.0);
  EXPECT_NO_THROW(MeasuredFromTable(Table(7, -kMaxRecordedAngle), "rig.csv"));
}

TEST(MeasuredAngles, BeyondTheSanityBoundIsBadInput) {
  try {
    MeasuredFromTable(Table(7, 2e4), "rig.csv");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("rig.csv:9: column 'q_knee': value 20000 out of range, expected |x| <= 10000"),
              std::string::npos) << m;
  }
}

TEST(MeasuredAngles, HumanJointRangeIsASeparateCheck) {
  EXPECT_NO_THROW(CheckHumanJointRange(MeasuredFromTable(Table(7, -6.28), "leg.csv")));
  try {
    CheckHumanJointRange(MeasuredFromTable(Table(12, -7.5), "leg.csv"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("leg.csv:14: column 'q_knee': angle -7.5 rad is beyond a human joint's range, "
                     "expected |q| <= 6.28"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// A 2 s record at 1 kHz with EMG, optionally non-uniform and with a measured qd_knee column.
MeasuredData Record(bool uniform, bool qd_column) {
  CsvTable t;
  t.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "emg_VM"};
  if (qd_column) t.names.push_back("qd_knee");
  t.columns.assign(t.names.size(), {});
  for (int i = 0; i < 2000; ++i) {
    const double ti = 1e-3 * i + (uniform ? 0.0 : 3e-4 * (i % 3));
    const double v[7] = {ti, 0.3 * std::sin(3 * ti), -0.6 + 0.4 * std::cos(5 * ti), 1.0, 2.0, 0.01 * std::sin(90 * ti),
                         -2.0 * std::sin(5 * ti)};
    for (size_t c = 0; c < t.names.size(); ++c) t.columns[c].push_back(v[c]);
    t.line_of_row.push_back(i + 2);
  }
  return MeasuredFromTable(t, "record.csv");
}

// DeriveKinematics taking the record's columns gives what the copying one gives, to the bit.
TEST(DeriveKinematics, TakingTheColumnsEqualsCopyingThem) {
  for (bool uniform : {true, false})
    for (bool qd_column : {false, true}) {
      SCOPED_TRACE(std::to_string(uniform) + std::to_string(qd_column));
      const MeasuredData d = Record(uniform, qd_column);
      const Kinematics a = DeriveKinematics(d, 15.0);
      MeasuredData taken = d;
      const Kinematics b = DeriveKinematics(std::move(taken), 15.0);
      EXPECT_EQ(taken.size(), 0u);
      EXPECT_TRUE(taken.table.columns.empty());
      EXPECT_EQ(a.t, b.t);
      for (int j = 0; j < 2; ++j) {
        EXPECT_EQ(a.q[j], b.q[j]);
        EXPECT_EQ(a.qd[j], b.qd[j]);
        EXPECT_EQ(a.qdd[j], b.qdd[j]);
      }
      EXPECT_EQ(a.emg, b.emg);
      EXPECT_EQ(a.resampled, b.resampled);
      EXPECT_EQ(a.derivative_source, b.derivative_source);
    }
}

}  // namespace
}  // namespace exotwin
