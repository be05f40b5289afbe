// OpenSim storage reader (formats/opensim_storage.h): every header variant, and bad input that must
// throw InputError naming the file and the line.
#include "formats/opensim_storage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "tests/expect_input_error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

using testing::ExpectInputError;


// Expects ParseStorage(text) to throw InputError naming the file and every piece.
void ExpectError(const std::string& text, std::vector<std::string> pieces) {
  pieces.push_back("f.sto: ");
  ExpectInputError([&] { ParseStorage(text, "f.sto"); }, pieces);
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
  ExpectInputError([&] { t.AngleRad("q"); }, {"k.sto", "inDegrees"});
  EXPECT_THROW(t.Column("nope", "angle"), InputError);
}

TEST(OpenSimStorage, ReadsFilesAndNamesUnreadableOnes) {
  const testing::ScopedTempDir dir_tmp("sto");
  const std::string dir = dir_tmp.path();
  std::ofstream(dir + "/a.sto") << "endheader\ntime a\n0 1\n1 2\n";
  EXPECT_EQ(ReadStorage(dir + "/a.sto").rows(), 2u);
  ExpectInputError([&] { ReadStorage(dir + "/missing.sto"); }, {"missing.sto", "cannot open"});
}

TEST(OpenSimStorage, SimmCountsWithoutEquals) {
  const StorageTable t = ParseStorage("name walk.mot\ndatacolumns 2\ndatarows 2\nrange 0 1\ninDegrees=no\n"
                                      "endheader\ntime q\n0 1\n1 2\n", "s.mot");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.endheader_line, 6);
  ExpectError("datacolumns 3\nendheader\ntime a\n0 1\n1 1\n", {"line 3", "nColumns=3"});
  ExpectError("datarows 3\nendheader\ntime a\n0 1\n1 1\n", {"nRows=3", "2 rows"});
  ExpectError("datarows x\nendheader\ntime a\n0 1\n1 1\n", {"line 1", "non-negative integer"});
}

TEST(OpenSimStorage, UnstatedAngleUnitNamesTheHeaderLine) {
  const StorageTable t = ParseStorage("ik\nnRows=2\nendheader\ntime q\n0 1\n1 2\n", "k.sto");
  ExpectInputError([&] { t.AngleRad("q"); }, {"k.sto: line 3", "inDegrees"});
}

TEST(OpenSimStorage, WriteStorageRoundTripsThroughTheReader) {
  const testing::ScopedTempDir tmp("sto_w");
  const std::string path = tmp.path() + "/out.sto";
  const std::vector<double> t = {0.0, 0.001, 0.002}, q = {0.1, -1.0 / 3.0, 2e-300}, tau = {-12.5, 1e300, M_PI};
  WriteStorage(path, "out.sto", {"time", "q_knee", "tau_knee"}, {&t, &q, &tau}, false, {"a free line"});
  const StorageTable r = ReadStorage(path);
  EXPECT_EQ(r.in_degrees, 0);
  EXPECT_EQ(r.endheader_line, 7);  // name, version, nRows, nColumns, inDegrees, note, endheader
  EXPECT_EQ(r.names, (std::vector<std::string>{"time", "q_knee", "tau_knee"}));
  EXPECT_EQ(r.Time(), t);  // "%.17g": bit-identical
  EXPECT_EQ(r.AngleRad("q_knee"), q);
  EXPECT_EQ(r.Column("tau_knee", ""), tau);
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  EXPECT_EQ(text.substr(0, 42), "out.sto\nversion=1\nnRows=3\nnColumns=3\ninDeg");
  EXPECT_NE(text.find("endheader\ntime\tq_knee\ttau_knee\n0\t0.1\t"), std::string::npos) << text;
  ExpectInputError([&] { WriteStorage(path, "x", {"t", "q"}, {&t, &q}, false); }, {"no 'time'"});
  // Missing folders are created (core/output_path.h); a file in their way is bad input.
  std::ofstream(tmp.path() + "/f") << "x";
  ExpectInputError([&] { WriteStorage(tmp.path() + "/f/x.sto", "x", {"time"}, {&t}, false); },
                   {"/f: exists and is not a folder"});
}

TEST(OpenSimStorage, CsvToStorageKeepsEveryColumnAndValue) {
  const testing::ScopedTempDir tmp("sto_c");
  const std::string dir = tmp.path();
  std::ofstream(dir + "/measured.csv") << "# a comment\nt,q_hip,tau_hip\n0,0.5,1.25\n0.001,0.30000000000000004,-7\n";
  CsvToStorage(dir + "/measured.csv", dir + "/measured.sto");
  const StorageTable r = ReadStorage(dir + "/measured.sto");
  EXPECT_EQ(r.names, (std::vector<std::string>{"time", "q_hip", "tau_hip"}));
  EXPECT_EQ(r.in_degrees, 0);
  EXPECT_EQ(r.AngleRad("q_hip"), (std::vector<double>{0.5, 0.30000000000000004}));
  EXPECT_EQ(r.Column("tau_hip", ""), (std::vector<double>{1.25, -7}));
  std::ofstream(dir + "/x.csv") << "time_s,q\n0,1\n";
  ExpectInputError([&] { CsvToStorage(dir + "/x.csv", dir + "/x.sto"); }, {"x.csv", "no column 't'"});
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
