// OpenSim storage reader (analysis/opensim_storage.h): every header variant, and bad input that must
// throw InputError naming the file and the line.
#include "analysis/opensim_storage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

// Expects f() to throw InputError whose message contains every piece.
template <typename F>
void ExpectThrows(F f, const std::vector<std::string>& pieces) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    for (const auto& p : pieces) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  }
}

// Expects ParseStorage(text) to throw InputError naming the file and every piece.
void ExpectError(const std::string& text, std::vector<std::string> pieces) {
  pieces.push_back("f.sto: ");
  ExpectThrows([&] { ParseStorage(text, "f.sto"); }, pieces);
}

TEST(OpenSimStorage, VersionOneHeaderInDegrees) {
  const StorageTable t = ParseStorage(
      "Coordinates\nversion=1\nnRows=3\nnColumns=3\ninDegrees=yes\n\nUnits are S.I. units\nendheader\n"
      "time\thip_flexion_r\tknee_angle_r\n"
      "      0.00000000\t     90.0\t   -45.0\n"
      "      0.01000000\t     80.0\t   -30.0\n"
      "      0.02000000\t     70.0\t   -15.0\n",
      "ik.sto");
  EXPECT_EQ(t.rows(), 3u);
  EXPECT_EQ(t.in_degrees, 1);
  EXPECT_EQ(t.names_line, 9);
  EXPECT_EQ(t.line_of_row[0], 10);
  EXPECT_DOUBLE_EQ(t.Time()[2], 0.02);
  const std::vector<double> q = t.AngleRad("knee_angle_r");
  EXPECT_NEAR(q[0], -M_PI / 4, 1e-15);
  EXPECT_DOUBLE_EQ(t.Column("hip_flexion_r", "")[1], 80.0);
}

TEST(OpenSimStorage, InDegreesNoKeepsRadians) {
  const StorageTable t = ParseStorage("version=1\ninDegrees=no\nendheader\ntime q\n0 0.5\n1 0.25\n", "a.mot");
  EXPECT_EQ(t.in_degrees, 0);
  EXPECT_DOUBLE_EQ(t.AngleRad("q")[0], 0.5);
}

TEST(OpenSimStorage, TrailingTabsAndSpacesAreNoColumns) {
  // As CEINMS's emgFilt.sto: no version line, indented values, a tab at the end of every line.
  const StorageTable t = ParseStorage(
      "Normalized EMG Linear Envelopes\nnRows=2\nnColumns=3\n\nendheader\n"
      "time\t  soleus_r\t med_gas_r\t\n0\t  0.07\t  0.19\t\n0.01\t  0.06\t  0.17\t  \r\n",
      "emg.sto");
  ASSERT_EQ(t.names.size(), 3u);
  EXPECT_EQ(t.names[1], "soleus_r");
  EXPECT_DOUBLE_EQ(t.Column("med_gas_r", "")[1], 0.17);
  EXPECT_EQ(t.in_degrees, -1);
}

TEST(OpenSimStorage, HeaderlessSpaceSeparated) {
  const StorageTable t = ParseStorage("time  a  b\n0 1 2\n\n0.5 3 4   \n", "h.sto");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.names_line, 1);
  EXPECT_DOUBLE_EQ(t.Column("b", "")[1], 4.0);
  EXPECT_EQ(t.line_of_row[1], 4);
}

TEST(OpenSimStorage, TimeNeedNotBeFirst) {
  const StorageTable t = ParseStorage("endheader\na time\n1 0\n2 1\n", "x.sto");
  EXPECT_DOUBLE_EQ(t.Time()[1], 1.0);
}

TEST(OpenSimStorage, HeaderWithoutEndheader) { ExpectError("version=1\nnRows=2\ntimes a\n0 1\n", {"line 1", "endheader"}); }

TEST(OpenSimStorage, MissingTimeColumn) { ExpectError("endheader\nt a\n0 1\n1 2\n", {"line 2", "'time'"}); }

TEST(OpenSimStorage, FewerValuesThanColumnNames) {
  ExpectError("endheader\ntime a b\n0 1 2\n0.1 1\n", {"line 4", "2 values, 3 column names"});
}

TEST(OpenSimStorage, MoreValuesThanColumnNames) {
  ExpectError("time\ta\n0\t1\t2\n1\t2\t3\n", {"line 2", "3 values, 2 column names"});
}

TEST(OpenSimStorage, NonMonotonicTime) {
  ExpectError("endheader\ntime a\n0 1\n0.2 1\n0.1 1\n", {"line 5", "does not increase"});
  ExpectError("endheader\ntime a\n0 1\n0 1\n", {"line 4", "does not increase"});
}

TEST(OpenSimStorage, NotANumber) { ExpectError("endheader\ntime a\n0 1\n1 x2\n", {"line 4", "'x2'", "column 'a'"}); }

TEST(OpenSimStorage, NonFiniteTime) { ExpectError("endheader\ntime a\n0 1\nnan 1\n", {"line 4", "not finite"}); }

TEST(OpenSimStorage, BadInDegrees) { ExpectError("inDegrees=maybe\nendheader\ntime a\n0 1\n1 1\n", {"line 1", "yes or no"}); }

TEST(OpenSimStorage, RowCountDisagreesWithHeader) {
  ExpectError("nRows=3\nendheader\ntime a\n0 1\n1 1\n", {"nRows=3", "2 rows"});
}

TEST(OpenSimStorage, ColumnCountDisagreesWithHeader) {
  ExpectError("nColumns=3\nendheader\ntime a\n0 1\n1 1\n", {"line 3", "nColumns=3"});
}

TEST(OpenSimStorage, RepeatedColumn) { ExpectError("endheader\ntime a a\n0 1 1\n1 1 1\n", {"line 2", "twice"}); }

TEST(OpenSimStorage, EmptyOrTooShort) {
  ExpectError("", {"empty"});
  ExpectError("endheader\ntime a\n0 1\n", {"fewer than 2 rows"});
  ExpectError("endheader\n\n", {"no column names"});
}

TEST(OpenSimStorage, AngleUnitMustBeStated) {
  const StorageTable t = ParseStorage("endheader\ntime q\n0 1\n1 2\n", "k.sto");
  ExpectThrows([&] { t.AngleRad("q"); }, {"k.sto", "inDegrees"});
  EXPECT_THROW(t.Column("nope", "angle"), InputError);
}

TEST(OpenSimStorage, ReadsFilesAndNamesUnreadableOnes) {
  const testing::ScopedTempDir dir_tmp("sto");
  const std::string dir = dir_tmp.path();
  std::ofstream(dir + "/a.sto") << "endheader\ntime a\n0 1\n1 2\n";
  EXPECT_EQ(ReadStorage(dir + "/a.sto").rows(), 2u);
  ExpectThrows([&] { ReadStorage(dir + "/missing.sto"); }, {"missing.sto", "cannot open"});
}

TEST(OpenSimStorage, ReadsTheRealRecording) {
  const std::string dir = std::string(EXOTWIN_SOURCE_DIR) + "/../shared/data/real_human/ceinms_lowerlimb_walk36";
  if (!std::ifstream(dir + "/ik.sto")) GTEST_SKIP() << "shared/data not beside the project";
  for (const char* f : {"emgFilt.sto", "ik.sto", "id.sto"}) {
    const StorageTable t = ReadStorage(dir + "/" + f);
    EXPECT_EQ(t.rows(), 6097u) << f;
    EXPECT_NEAR(t.Time().back(), 60.96, 1e-9) << f;
  }
  EXPECT_EQ(ReadStorage(dir + "/ik.sto").in_degrees, 1);
  EXPECT_EQ(ReadStorage(dir + "/id.sto").in_degrees, 0);
  EXPECT_EQ(ReadStorage(dir + "/emgFilt.sto").names.size(), 10u);
}

}  // namespace
}  // namespace exotwin
