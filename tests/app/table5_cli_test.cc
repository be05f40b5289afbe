// `exotwin table5` plant options on the command line (app/cmd_table5.cc): bad input is exit 2 with a
// message naming the option or the file, before anything runs or is written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/app/cli_test_util.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

TEST(Table5Cli, BadPlantInputIsExit2BeforeAnyRun) {
  const testing::ScopedTempDir tmp("table5_cli");
  const std::string out = tmp.path() + "/out";
  const std::string plants = std::string(EXOTWIN_SOURCE_DIR) + "/data/plants/";
  const std::string muscles = tmp.path() + "/muscles.yaml";
  WriteText(muscles, "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n"
                      "effects:\n  - {name: muscle_activity, joint: knee, value: 1, weights: {vl: 0.1}}\n");
  struct Case {
    std::string args, expect;
  } cases[] = {
      {"--realistic --plant " + plants + "exowheel_realistic.yaml", "--realistic: names its own plant files"},
      {"--plant " + tmp.path() + "/missing.yaml", "missing.yaml"},
      {"--plant-worn " + muscles, "effects[0]"},  // EMG is a record's input, not the plant's
      {"--diagnose --fit inverse", "table5 --fit: 'inverse', expected torque or motion"},
      {"--fit motion", "table5 --fit motion: expected --diagnose with it"},
  };
  for (const Case& c : cases) {
    const auto r = RunExotwin("table5 --subjects S1 --out " + out + " " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args << ": wrote " << out;
  }
}

}  // namespace
}  // namespace exotwin
