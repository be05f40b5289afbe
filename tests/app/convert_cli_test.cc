// `exotwin convert` and `--map` through the command line (DESIGN.md "Column map"), on the shipped
// real-rig example (examples/real_rig/): convert's output re-reads as what the map gives; predict
// --map equals predict on the converted file; a record turning through 11 rad is accepted for the
// device alone and refused for a model with a human; a bad map exits 2 and writes nothing.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

const std::string kDir = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/";
const std::string kMap = kDir + "dfki_double_pendulum_A0.map.yaml";

// The file without its '#' comment lines.
std::string Data(const std::string& path) {
  std::istringstream in(testing::ReadText(path));
  std::string out, line;
  while (std::getline(in, line))
    if (line.rfind("#", 0) != 0) out += line + "\n";
  return out;
}

TEST(ConvertCli, OutputRereadsAsWhatTheMapGives) {
  const testing::ScopedTempDir tmp("convert");
  const std::string dir = tmp.path();
  const std::string in = kDir + "trajectory_11.csv";
  const auto r = RunExotwin("convert --map " + kMap + " " + in + " --out " + dir + "/data.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("convert: map " + kMap + " on " + in + ": 3857 rows in, 3857 out"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("tau_hip <- -tau_meas1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("jitter"), std::string::npos) << r.output;

  const MeasuredData converted = ReadMeasuredCsv(dir + "/data.csv");
  const MeasuredData mapped = ApplyColumnMap(ReadColumnMap(kMap), ReadCsv(in), in);
  EXPECT_EQ(converted.table.names, mapped.table.names);
  EXPECT_EQ(converted.table.columns, mapped.table.columns);  // bit for bit (shortest round-trip text)
  const std::string text = testing::ReadText(dir + "/data.csv");
  EXPECT_NE(text.find("# source: " + in), std::string::npos);
  EXPECT_NE(text.find("# map: " + kMap), std::string::npos);
}

TEST(ConvertCli, PredictWithMapEqualsPredictOnTheConvertedFile) {
  const testing::ScopedTempDir tmp("convert_predict");
  const std::string dir = tmp.path();
  const std::string in = kDir + "trajectory_05.csv";
  ASSERT_EQ(RunExotwin("convert --map " + kMap + " " + in + " --out " + dir + "/data.csv").exit_code, 0);
  const auto a = RunExotwin("predict --params " + kDir + "model.yaml --measured " + in + " --map " + kMap +
                            " --out " + dir + "/a.csv");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_NE(a.output.find("predict: map "), std::string::npos) << a.output;
  const auto b = RunExotwin("predict --params " + kDir + "model.yaml --measured " + dir + "/data.csv --out " +
                            dir + "/b.csv");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string pa = Data(dir + "/a.csv"), pb = Data(dir + "/b.csv");
  EXPECT_GT(pa.size(), 4000u * 3);
  EXPECT_TRUE(pa == pb) << "predict --map and predict on the converted file differ";
}

// trajectory_05's second link turns through 11 rad: fine for the rig alone (above), not for a leg.
TEST(ConvertCli, HumanModelRefusesARecordBeyondAHumanJointsRange) {
  const testing::ScopedTempDir tmp("convert_human");
  const std::string dir = tmp.path();
  WriteText(dir + "/leg.yaml",
            "L1: 0.41\nexo:   {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n"
            "human: {J1: 1.69, J2: 0.37, X1: 4.54, X2: 1.20, Y1: -0.16, Y2: 0.42}\npassive: none\n");
  const auto r = RunExotwin("predict --params " + dir + "/leg.yaml --measured " + kDir +
                            "trajectory_05.csv --map " + kMap + " --out " + dir + "/p.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("trajectory_05.csv:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": column 'q_knee': angle "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("expected |q| <= 6.28"), std::string::npos) << r.output;
  EXPECT_FALSE(std::ifstream(dir + "/p.csv").good());
}

TEST(ConvertCli, BadMapExitsTwoAndWritesNothing) {
  const testing::ScopedTempDir tmp("convert_bad");
  const std::string dir = tmp.path();
  std::string map = testing::ReadText(kMap);
  map.replace(map.find("sign: -1}"), 9, "scale: 0}");
  WriteText(dir + "/bad.yaml", map);
  const auto r = RunExotwin("convert --map " + dir + "/bad.yaml " + kDir + "trajectory_11.csv --out " + dir +
                            "/data.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir + "/bad.yaml: columns.tau_hip.scale: expected a non-zero number"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::ifstream(dir + "/data.csv").good());
  EXPECT_FALSE(std::ifstream(dir + "/data.csv.tmp").good());
}

TEST(ConvertCli, UsageErrors) {
  EXPECT_EQ(RunExotwin("convert " + kDir + "trajectory_11.csv --out /tmp/x.csv").exit_code, 2);  // no --map
  const auto r = RunExotwin("convert --map " + kMap + " /nonexistent/in.csv --out /tmp/x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/in.csv: cannot open file"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace exotwin
