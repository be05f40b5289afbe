// Column maps: rename, scale, offset, units and sign against hand-computed values; rows repeating a
// time stamp averaged / kept first / rejected, counted and located; the time step and its jitter
// reported; the shipped map of examples/real_rig/ on its shipped records gives the README's mapping;
// bad maps throw InputError naming the map file, the key and what was expected.
#include "tests/temp_dir.h"
#include "formats/column_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/error.h"
#include "core/units.h"

namespace exotwin {
namespace {

std::string TempPath(const std::string& name) {
  static const testing::ScopedTempDir tmp("map");  // the suite's folder, removed at exit
  const std::string& dir = tmp.path();
  return dir + "/" + name;
}

void Spit(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// A foreign log: time in ms, one angle in degrees, torques with the actuator's sign, an EMG in mV and
// a column the map leaves out. Data row i is on line i + 3 (a comment, then the header).
std::string ForeignCsv(int n = 30) {
  std::ostringstream os;
  os << "# a foreign rig\nms,deg1,rad2,m1,m2,e_mv,unused\n";
  for (int i = 0; i < n; ++i)
    os << 2 * i << "," << 10 + i << "," << 0.01 * i << "," << 0.5 * i << "," << -0.25 * i << "," << 3 * i
       << ",99\n";
  return os.str();
}

const char kForeignMap[] =
    "# comment\n"
    "columns:\n"
    "  t:        {from: ms, unit: ms}\n"
    "  q_hip:    {from: deg1, unit: deg, offset: -90}\n"
    "  q_knee:   {from: rad2, scale: 2, offset: 0.1}\n"
    "  tau_hip:  {from: m1, sign: -1}\n"
    "  tau_knee: {from: m2, scale: 0.5, sign: -1}\n"
    "  emg_VM:   {from: e_mv, unit: mV}\n";

struct Files {
  std::string csv, map;
};
Files Write(const std::string& tag, const std::string& csv, const std::string& map) {
  Files f{TempPath(tag + ".csv"), TempPath(tag + ".yaml")};
  Spit(f.csv, csv);
  Spit(f.map, map);
  return f;
}

TEST(ColumnMap, RenameScaleOffsetUnitsAndSignAgainstHandComputedValues) {
  const Files f = Write("basic", ForeignCsv(), kForeignMap);
  MapReport rep;
  const MeasuredData d = ReadMeasured(f.csv, f.map, 20, &rep);
  ASSERT_EQ(d.size(), 30u);
  EXPECT_EQ(d.table.names, (std::vector<std::string>{"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "emg_VM"}));
  for (int i = 0; i < 30; ++i) {
    EXPECT_DOUBLE_EQ(d.t()[i], 2e-3 * i);
    EXPECT_NEAR(d.q_hip()[i], (10.0 + i - 90.0) * kRadPerDeg, 1e-15);  // offset in degrees, then to rad
    EXPECT_DOUBLE_EQ(d.q_knee()[i], 2 * 0.01 * i + 0.1);
    EXPECT_DOUBLE_EQ(d.tau_hip()[i], -0.5 * i);
    EXPECT_DOUBLE_EQ(d.tau_knee()[i], 0.125 * i);
    EXPECT_DOUBLE_EQ((*d.Column("emg_VM"))[i], 3e-3 * i);
    EXPECT_EQ(d.table.line_of_row[i], i + 3);  // messages keep naming the foreign file's lines
  }
  EXPECT_EQ(d.Column("unused"), nullptr);
  EXPECT_EQ(rep.rows_in, 30u);
  EXPECT_EQ(rep.rows_out, 30u);
  EXPECT_EQ(rep.repeated_stamps, 0u);
  EXPECT_NEAR(rep.dt_median, 2e-3, 1e-15);
  EXPECT_NEAR(rep.jitter, 0.0, 1e-9);
  ASSERT_EQ(rep.mapped.size(), 6u);
  EXPECT_EQ(rep.mapped[3], "tau_hip <- -m1");
  EXPECT_EQ(rep.mapped[4], "tau_knee <- -0.5 * m2");
  EXPECT_NE(rep.Summary().find("repeated time stamps: none"), std::string::npos) << rep.Summary();
}

TEST(ColumnMap, ShorthandAndRequiredTargetsFirst) {
  const Files f = Write("short", ForeignCsv(),
                        "columns:\n  emg_VM: e_mv\n  tau_knee: m2\n  tau_hip: m1\n  q_knee: rad2\n"
                        "  q_hip: deg1\n  t: ms\n");
  const MeasuredData d = ReadMeasured(f.csv, f.map);
  EXPECT_EQ(d.table.names, (std::vector<std::string>{"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "emg_VM"}));
  EXPECT_DOUBLE_EQ(d.t()[3], 6.0);
  EXPECT_DOUBLE_EQ(d.q_hip()[3], 13.0);
}

// Rows 2-4 share t = 0.004, rows 10-11 share t = 0.020; steps otherwise 2 ms.
std::string RepeatingCsv() {
  std::ostringstream os;
  os << "time,a,b,c,d\n";
  const double t[] = {0, 0.002, 0.004, 0.004, 0.004, 0.006, 0.008, 0.010, 0.012, 0.014, 0.016, 0.016,
                      0.018, 0.020, 0.022, 0.024, 0.026, 0.028, 0.030, 0.032, 0.034, 0.036, 0.038};
  int i = 0;
  for (double ti : t) os << ti << "," << i << "," << 2 * i << "," << -i << "," << 0.5 * i << "\n", ++i;
  return os.str();
}
const char kRepeatingMap[] = "columns: {t: time, q_hip: a, q_knee: b, tau_hip: c, tau_knee: d}\n";

TEST(ColumnMap, RepeatedTimeStampsAveragedCountedAndLocated) {
  const Files f = Write("dup", RepeatingCsv(), std::string(kRepeatingMap) + "time: {duplicates: average}\n");
  MapReport rep;
  const MeasuredData d = ReadMeasured(f.csv, f.map, 5, &rep);
  EXPECT_EQ(rep.rows_in, 23u);
  EXPECT_EQ(rep.rows_out, 20u);
  EXPECT_EQ(rep.repeated_stamps, 2u);
  EXPECT_EQ(rep.rows_merged, 3u);
  EXPECT_EQ(rep.repeated_lines, (std::vector<int>{5, 6, 13}));  // header on line 1, row i on line i + 2
  ASSERT_EQ(d.size(), 20u);
  EXPECT_DOUBLE_EQ(d.t()[2], 0.004);
  EXPECT_DOUBLE_EQ(d.q_hip()[2], (2 + 3 + 4) / 3.0);
  EXPECT_DOUBLE_EQ(d.q_knee()[2], (4 + 6 + 8) / 3.0);
  EXPECT_DOUBLE_EQ(d.tau_hip()[2], -(2 + 3 + 4) / 3.0);
  EXPECT_DOUBLE_EQ(d.q_hip()[3], 5);                 // the rows after a merge are untouched
  EXPECT_DOUBLE_EQ(d.q_hip()[8], (10 + 11) / 2.0);   // second group
  EXPECT_EQ(d.table.line_of_row[2], 4);            // a merged row keeps its first line
  EXPECT_NE(rep.Summary().find("repeated time stamps: 2 (3 rows merged by average; lines 5 6 13)"),
            std::string::npos) << rep.Summary();
  // Time step after merging: 2 ms everywhere.
  EXPECT_NEAR(rep.dt_median, 0.002, 1e-12);
  EXPECT_NEAR(rep.dt_max, 0.002, 1e-12);
}

TEST(ColumnMap, RepeatedTimeStampsFirstKeptOrRejected) {
  const Files f = Write("dupfirst", RepeatingCsv(), std::string(kRepeatingMap) + "time: {duplicates: first}\n");
  MapReport rep;
  const MeasuredData d = ReadMeasured(f.csv, f.map, 5, &rep);
  ASSERT_EQ(d.size(), 20u);
  EXPECT_DOUBLE_EQ(d.q_hip()[2], 2);
  EXPECT_DOUBLE_EQ(d.q_hip()[8], 10);
  EXPECT_EQ(rep.rows_merged, 3u);

  const Files e = Write("duperr", RepeatingCsv(), std::string(kRepeatingMap) + "time: {duplicates: error}\n");
  try {
    ReadMeasured(e.csv, e.map, 5);
    FAIL() << "expected InputError";
  } catch (const InputError& x) {
    const std::string m = x.what();
    EXPECT_NE(m.find(e.csv + ":5: column 'time' (t): time stamp 0.004 repeats the one on line 4"), std::string::npos) << m;
    EXPECT_NE(m.find("time.duplicates is error"), std::string::npos) << m;
  }
}

TEST(ColumnMap, JitterReported) {
  std::ostringstream os;
  os << "time,a,b,c,d\n";
  double t = 0;
  for (int i = 0; i < 101; ++i) {
    os << t << ",0,0,0,0\n";
    t += i % 2 ? 0.0011 : 0.0009;  // 1 ms +- 0.1 ms
  }
  const Files f = Write("jitter", os.str(), kRepeatingMap);
  MapReport rep;
  ReadMeasured(f.csv, f.map, 20, &rep);
  EXPECT_NEAR(rep.dt_min, 0.0009, 1e-12);
  EXPECT_NEAR(rep.dt_max, 0.0011, 1e-12);
  EXPECT_NEAR(rep.dt_p99, 0.0011, 1e-12);
  EXPECT_NEAR(rep.dt_median, 0.001, 1e-12);  // 50 steps of each: halfway
  EXPECT_NEAR(rep.jitter, 0.1, 1e-6);
}

// The shipped example: the map for the development set gives the README's mapping on the shipped
// records, value for value against the raw file; trajectory_05's second link turns through 11 rad.
TEST(ColumnMap, ShippedMapOnShippedRecords) {
  const std::string dir = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/";
  for (const char* name : {"trajectory_05.csv", "trajectory_11.csv"}) {
    SCOPED_TRACE(name);
    const CsvTable raw = ReadCsv(dir + name);
    MapReport rep;
    const MeasuredData d = ReadMeasured(dir + name, dir + "dfki_double_pendulum_A0.map.yaml", 20, &rep);
    ASSERT_EQ(d.size(), raw.rows());  // no repeated stamps in these two
    EXPECT_EQ(rep.repeated_stamps, 0u);
    const auto& col = [&](const char* n) { return raw.columns[raw.Find(n)]; };
    for (size_t i = 0; i < d.size(); ++i) {
      ASSERT_EQ(d.t()[i], col("time")[i]);
      ASSERT_EQ(d.q_hip()[i], col("pos_meas1")[i]);
      ASSERT_EQ(d.q_knee()[i], col("pos_meas2")[i]);
      ASSERT_EQ(d.tau_hip()[i], -col("tau_meas1")[i]);
      ASSERT_EQ(d.tau_knee()[i], -col("tau_meas2")[i]);
      ASSERT_EQ((*d.Column("cmd_hip"))[i], col("tau_con1")[i]);
    }
    EXPECT_GT(rep.jitter, 0.0);  // the rig's steps jitter
  }
  const MeasuredData d = ReadMeasured(dir + "trajectory_05.csv", dir + "dfki_double_pendulum_A0.map.yaml");
  const auto [lo, hi] = std::minmax_element(d.q_knee().begin(), d.q_knee().end());
  EXPECT_GT(*hi - *lo, 11.0);
  EXPECT_GT(*hi, kMaxHumanJointAngle);
  EXPECT_THROW(CheckHumanJointRange(d), InputError);
}

// ---- bad maps ----
void ExpectMapError(const std::string& tag, const std::string& csv, const std::string& map,
                    const std::vector<std::string>& must_contain) {
  const Files f = Write(tag, csv, map);
  try {
    ReadMeasured(f.csv, f.map);
    ADD_FAILURE() << tag << ": expected InputError";
  } catch (const InputError& e) {
    for (const std::string& s : must_contain) {
      const std::string want = s == "@map" ? f.map : s == "@csv" ? f.csv : s;
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << tag << ": '" << want << "' in: " << e.what();
    }
  }
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  return s.replace(s.find(from), from.size(), to);
}

TEST(ColumnMapBadInput, EachCaseNamesFileKeyAndExpectation) {
  const std::string csv = ForeignCsv(), m = kForeignMap;
  ExpectMapError("missingcol", csv, Replace(m, "from: rad2", "from: pos9"),
                 {"@map", "columns.q_knee.from (line 5)", "missing required column 'pos9' in", "@csv",
                  "expected one of its columns: ms, deg1, rad2"});
  ExpectMapError("zeroscale", csv, Replace(m, "scale: 2", "scale: 0"),
                 {"@map", "columns.q_knee.scale", "expected a non-zero number", "(line 5)"});
  ExpectMapError("unknowntarget", csv, m + "  q_ankle: {from: rad2}\n",
                 {"@map", "columns.q_ankle", "unknown key (line 9)", "expected one of: t, q_hip"});
  ExpectMapError("emptyemg", csv, m + "  emg_: {from: e_mv}\n", {"@map", "columns.emg_", "unknown key"});
  ExpectMapError("missingtarget", csv, Replace(m, "  tau_knee: {from: m2, scale: 0.5, sign: -1}\n", ""),
                 {"@map", "columns: missing required target 'tau_knee'", "expected t, q_hip"});
  ExpectMapError("nofrom", csv, Replace(m, "{from: m1, sign: -1}", "{sign: -1}"),
                 {"@map", "columns.tau_hip.from: missing", "expected the name of the source column"});
  ExpectMapError("badsign", csv, Replace(m, "sign: -1}", "sign: 0.5}"),
                 {"@map", "columns.tau_hip.sign", "expected +1 or -1"});
  ExpectMapError("badunit", csv, Replace(m, "unit: deg", "unit: grad"),
                 {"@map", "columns.q_hip.unit", "'grad' is not a unit of q_hip", "expected one of: rad, deg"});
  ExpectMapError("unknownkey", csv, Replace(m, "{from: m1,", "{from: m1, gain: 2,"),
                 {"@map", "columns.tau_hip.gain", "unknown key"});
  ExpectMapError("badduplicates", csv, m + "time: {duplicates: mean}\n",
                 {"@map", "time.duplicates", "'mean' is not one of: average, first, error"});
  ExpectMapError("malformed", csv, "columns:\n  t: {from: ms\n", {"@map", ": line ", "malformed YAML"});
  ExpectMapError("empty", csv, "", {"@map", "empty column map"});
  ExpectMapError("notmap", csv, "- a\n- b\n", {"@map", "expected a YAML mapping"});
  ExpectMapError("dupkey", csv, m + "  t: {from: ms}\n", {"@map", "columns.t", "duplicated key"});
  // 10 + i degrees with offset 900: beyond +-720 deg from the first row (line 3).
  ExpectMapError("deg720", csv, Replace(m, "offset: -90", "offset: 900"),
                 {"@csv", ":3: column 'deg1' (q_hip in deg", "line 4)", "910 deg is beyond +-720 deg",
                  "expected an angle in degrees"});
  // What the schema rejects names the map: a torque scaled beyond 1000 N m.
  ExpectMapError("schema", csv, Replace(m, "scale: 0.5", "scale: 1e6"),
                 {"@csv", "column 'tau_knee'", "expected |x| <= 1000", "after the column map", "@map"});
}

TEST(ColumnMapBadInput, MissingMapFile) {
  const std::string csv = TempPath("nomap.csv");
  Spit(csv, ForeignCsv());
  try {
    ReadMeasured(csv, "/nonexistent/map.yaml");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/map.yaml: cannot open column map file"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace exotwin
