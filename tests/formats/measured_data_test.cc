// Measured-data angles: a record may turn a joint through several revolutions (up to the sanity
// bound kMaxRecordedAngle); a human joint's range (2 pi) is a separate check naming file, line, column.
#include "formats/measured_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "dsp/butterworth.h"
#include "formats/number_text.h"
#include "tests/temp_dir.h"

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
  EXPECT_DOUBLE_EQ(d.q_knee()[7], 11.0);
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

// The required columns are views of the table (one copy of a record's data): a copy of the record
// views its own table, writes through column_at show in the table, an empty record has empty views.
TEST(MeasuredData, RequiredColumnsAreViewsOfTheTable) {
  const MeasuredData d = Record(true, true);
  EXPECT_EQ(&d.t(), &d.table.columns[0]);
  EXPECT_EQ(&d.tau_knee(), &d.table.columns[4]);
  EXPECT_EQ(d.size(), 2000u);
  MeasuredData c = d;
  EXPECT_EQ(&c.q_hip(), &c.table.columns[1]);
  c.column_at(kColQKnee)[7] = 1.25;
  EXPECT_EQ(c.table.columns[2][7], 1.25);
  EXPECT_NE(d.q_knee()[7], 1.25);
  const MeasuredData none;
  EXPECT_EQ(none.size(), 0u);
  EXPECT_TRUE(none.tau_hip().empty());
  CsvTable t = d.table;
  t.names[3] = "torque_hip";
  try {
    MakeMeasuredData(t, "rig.csv");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.csv: missing required column 'tau_hip'"), std::string::npos) << e.what();
  }
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


// TimeBaseLowPass (the sampling examined once, the filter designed once, several signals at a
// time) gives LowPassOnTimeBase's composition bit for bit: FiltFilt on a uniform record, through
// the median-step grid and back on a non-uniform one, the signals given whole or generated block by
// block; DeriveAngleRates gives DeriveKinematics' rates.
TEST(TimeBaseLowPass, EqualsFilteringOnTheTimeBaseBitForBit) {
  for (bool uniform : {true, false}) {
    SCOPED_TRACE(uniform ? "uniform" : "non-uniform");
    const MeasuredData d = Record(uniform, false);
    const Sampling s = ExamineSampling(d.t(), d.source);
    EXPECT_EQ(s.uniform, uniform);
    EXPECT_EQ(s.dt, MedianStep(d.t()));
    const auto sos = dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / s.dt, 7.0);
    const TimeBaseLowPass low(s, d.t(), 7.0, d.source);
    std::vector<double> xs[5] = {d.q_hip(), d.q_knee(), d.tau_hip(), *d.Column("emg_VM"), d.t()};
    std::vector<double> batched[5] = {xs[0], xs[1], xs[2], xs[3], xs[4]};
    std::vector<double>* bptr[5];
    for (int k = 0; k < 5; ++k) bptr[k] = &batched[k];
    low.Apply(bptr, 5);
    for (int k = 0; k < 5; ++k) {
      const std::vector<double> ref =
          uniform ? dsp::FiltFilt(sos, xs[k]) : Interpolate(s.grid, dsp::FiltFilt(sos, Interpolate(d.t(), xs[k], s.grid)), d.t());
      EXPECT_EQ(low(xs[k]), ref);
      EXPECT_EQ(TimeBaseLowPass(d.t(), 7.0, d.source)(xs[k]), ref);
      EXPECT_EQ(LowPassOnTimeBase(d.t(), xs[k], 7.0, d.source), ref);
      EXPECT_EQ(batched[k], ref);
    }
    // The same signals generated block by block (ApplyGenerated): the same bits.
    std::vector<double> generated[5];
    std::vector<double>* gptr[5];
    for (int k = 0; k < 5; ++k) generated[k].assign(d.size(), 0.0), gptr[k] = &generated[k];
    low.ApplyGenerated(gptr, 5, [&](size_t begin, size_t end) {
      for (int k = 0; k < 5; ++k) std::copy(xs[k].begin() + begin, xs[k].begin() + end, generated[k].begin() + begin);
    });
    for (int k = 0; k < 5; ++k) EXPECT_EQ(generated[k], batched[k]);
    const Kinematics k = DeriveKinematics(d, 15.0);
    for (int j = 0; j < 2; ++j) {
      const AngleRates r = DeriveAngleRates(s, d.t(), j == 0 ? d.q_hip() : d.q_knee(), 15.0, d.source);
      EXPECT_EQ(r.qd, k.qd[j]);
      EXPECT_EQ(r.qdd, k.qdd[j]);
      // Into vectors that held another cutoff's rates (their storage reused): the same bits.
      AngleRates into = DeriveAngleRates(s, d.t(), j == 0 ? d.q_hip() : d.q_knee(), 4.0, d.source);
      DeriveAngleRatesInto(s, d.t(), j == 0 ? d.q_hip() : d.q_knee(), 15.0, d.source, &into);
      EXPECT_EQ(into.qd, k.qd[j]);
      EXPECT_EQ(into.qdd, k.qdd[j]);
    }
    EXPECT_THROW(TimeBaseLowPass(s, d.t(), 600.0, d.source), InputError);  // above half the sample rate
  }
}

// MedianStep (radix selection on the steps' bit patterns, else selection) is the middle step of the sorted steps,
// the m/2-th smallest of m, on time bases a file gives (0.001 i printed and parsed back: a few
// distinct steps), two rates whose share puts the median at the boundary, a jittered clock, steps all
// distinct (the most passes), a step out of order (the selection) and short records.
TEST(MedianStep, IsTheMiddleOfTheSortedSteps) {
  auto Reference = [](const std::vector<double>& t) {
    std::vector<double> d(t.size() - 1);
    for (size_t i = 0; i + 1 < t.size(); ++i) d[i] = t[i + 1] - t[i];
    std::sort(d.begin(), d.end());
    return d[d.size() / 2];
  };
  Rng rng(7);
  std::vector<std::pair<std::string, std::vector<double>>> bases;
  for (size_t n : {2, 3, 100, 4097, 4098, 60001}) {
    std::vector<double> printed(n), two_rates(n), jittered(n), distinct(n);
    double tj = 0, td = 0;
    for (size_t i = 0; i < n; ++i) {
      printed[i] = std::stod(std::to_string(0.001 * static_cast<double>(i)));
      two_rates[i] = i <= n / 2 ? 0.001 * static_cast<double>(i) : 0.001 * static_cast<double>(n / 2) + 0.002 * static_cast<double>(i - n / 2);
      jittered[i] = tj, tj += rng.Uniform() < 0.2 ? 0.0011 : 0.001;
      distinct[i] = td, td += 0.001 * (1 + rng.Uniform());
    }
    for (auto& [name, t] : {std::make_pair("printed", printed), std::make_pair("two rates", two_rates),
                            std::make_pair("jittered", jittered), std::make_pair("distinct", distinct)})
      bases.emplace_back(std::string(name) + " n=" + std::to_string(n), t);
  }
  // Times out of order (a negative step): the selection, the same middle step.
  std::vector<double> unordered = bases.back().second;
  std::swap(unordered[10], unordered[11]);
  bases.emplace_back("one step negative", unordered);
  for (const auto& [name, t] : bases) {
    SCOPED_TRACE(name);
    EXPECT_EQ(MedianStep(t), Reference(t));
  }
  EXPECT_THROW(MedianStep({0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// A record as `run` writes it, with the columns a caller may leave out between the required ones:
// t, q_hip, cmd_hip, q_knee, tau_hip, ref_hip, tau_knee, state, emg_VM; n rows at 1 kHz (over 1 MB of
// text: the reader reads a piece in two halves at once). `set`: (column, row, text) put in place.
using Cell = std::tuple<std::string, size_t, std::string>;
std::string WriteRunLike(const testing::ScopedTempDir& tmp, const std::string& name, size_t n,
                         const std::vector<Cell>& set = {}) {
  const std::vector<std::string> names = {"t", "q_hip", "cmd_hip", "q_knee", "tau_hip", "ref_hip", "tau_knee", "state", "emg_VM"};
  std::string text = "# exotwin stream: complete rows end with a newline\n";
  for (size_t c = 0; c < names.size(); ++c) text += (c ? "," : "") + names[c];
  text += "\n";
  Rng rng(7);
  for (size_t i = 0; i < n; ++i) {
    for (size_t c = 0; c < names.size(); ++c) {
      std::string v = c == 0 ? std::to_string(1e-3 * static_cast<double>(i + 1)) : NumberText(rng.Uniform(-1, 1), 17);
      for (const Cell& x : set)
        if (std::get<0>(x) == names[c] && std::get<1>(x) == i) v = std::get<2>(x);
      text += (c ? "," : "") + v;
    }
    text += "\n";
  }
  const std::string path = tmp.File(name);
  std::ofstream(path) << text;
  return path;
}

MeasuredColumns KeepEmg() {
  return [](const std::string& n) { return n.rfind("emg_", 0) == 0; };
}

// The error text of reading `path` (unfiltered or with `keep`), "" when it reads.
std::string ReadError(const std::string& path, const MeasuredColumns& keep) {
  try {
    if (keep) ReadMeasuredCsv(path, 20, keep);
    else ReadMeasuredCsv(path, 20);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ReadMeasuredColumns, KeepsTheColumnsAskedForWithTheSameValuesAndLines) {
  const testing::ScopedTempDir tmp("measured_keep");
  const std::string path = WriteRunLike(tmp, "run.csv", 30000);
  const MeasuredData all = ReadMeasuredCsv(path);
  const MeasuredData some = ReadMeasuredCsv(path, 20, KeepEmg());
  ASSERT_EQ(all.size(), 30000u);
  EXPECT_EQ(some.table.names, (std::vector<std::string>{"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "emg_VM"}));
  for (const std::string& n : some.table.names) EXPECT_EQ(*some.Column(n), *all.Column(n)) << n;  // bit for bit
  EXPECT_EQ(some.table.line_of_row, all.table.line_of_row);
  ASSERT_EQ(some.table.dropped.size(), 3u);
  EXPECT_EQ(some.table.dropped[0].name, "cmd_hip");
  EXPECT_EQ(some.table.dropped[0].before, 2u);  // after t, q_hip
  EXPECT_EQ(some.table.dropped[2].name, "state");
  EXPECT_EQ(some.table.dropped[2].before, 5u);
  EXPECT_FALSE(some.one_joint);
}

TEST(ReadMeasuredColumns, AColumnLeftOutIsValidatedAsIfKept) {
  const testing::ScopedTempDir tmp("measured_keep_bad");
  // A schema column left out (cmd_hip, |x| <= 1000 N m, finite) in the first and in the second half of
  // the file; a column outside the schema (ref_hip) may hold anything numeric, kept or not.
  for (const size_t row : {size_t{17}, size_t{24000}}) {
    for (const std::string bad : {"2000", "nan"}) {
      const std::string path = WriteRunLike(tmp, "bad.csv", 30000, {{"cmd_hip", row, bad}});
      const std::string want = ReadError(path, {});
      EXPECT_NE(want.find(":" + std::to_string(row + 3) + ": column 'cmd_hip'"), std::string::npos) << want;
      EXPECT_EQ(ReadError(path, KeepEmg()), want);
    }
  }
  const std::string odd = WriteRunLike(tmp, "ref.csv", 3000, {{"ref_hip", 5, "inf"}});
  EXPECT_EQ(ReadError(odd, {}), "");
  EXPECT_EQ(ReadError(odd, KeepEmg()), "");
  // Two bad values: the first column in file order is reported, left out or not (cmd_hip before
  // q_knee, whose bad value comes first in the rows).
  {
    const std::string path = WriteRunLike(tmp, "two.csv", 3000, {{"cmd_hip", 2000, "1e9"}, {"q_knee", 0, "nan"}});
    const std::string want = ReadError(path, {});
    EXPECT_NE(want.find("column 'cmd_hip'"), std::string::npos) << want;
    EXPECT_EQ(ReadError(path, KeepEmg()), want);
  }
  // A number-less field in a column left out is still an error of the CSV.
  const std::string word = WriteRunLike(tmp, "word.csv", 3000, {{"state", 9, "x"}});
  EXPECT_FALSE(ReadError(word, KeepEmg()).empty());
  EXPECT_EQ(ReadError(word, KeepEmg()), ReadError(word, {}));
}

TEST(ReadMeasuredColumns, AHipColumnLeftOutStillMakesTheTableTwoJoint) {
  const testing::ScopedTempDir tmp("measured_keep_hip");
  const std::string path = tmp.File("knee.csv");
  std::string text = "t,q_knee,tau_knee,cmd_hip\n";
  for (int i = 0; i < 50; ++i) text += std::to_string(1e-3 * (i + 1)) + ",0.1,0.2,0.3\n";
  std::ofstream(path) << text;
  const std::string want = ReadError(path, {});
  EXPECT_NE(want, "");  // a hip column without q_hip: not a one-joint record
  EXPECT_EQ(ReadError(path, KeepEmg()), want);
}

}  // namespace
}  // namespace exotwin
