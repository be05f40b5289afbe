// `exotwin generate` + `exotwin diagnose` at the command line (EXOTWIN_BIN), the extended model
// loaded by predict, bad input, and a chain that is not the leg ("beyond the leg").
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "formats/csv_table.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

const std::string kS1 = std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml";

TEST(DiagnoseCli, FindsTheHiddenEffectAndPredictLoadsTheExtendedModel) {
  const testing::ScopedTempDir tmp("diag");
  const std::string d = tmp.path();
  auto r = RunExotwin("generate --params " + kS1 + " --seed 11 --effect coulomb_friction --joint knee"
                      " --duration 30 --rate 500 --out " + d + "/data.csv --truth " + d + "/truth.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LegParams truth = ReadModelFile(d + "/truth.yaml");
  ASSERT_EQ(truth.effects.size(), 1u);
  r = RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/data.csv --out " + d + "/out");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(testing::ReadText(d + "/out/diagnosis.json"));
  ASSERT_EQ(j["effects"].size(), 1u) << j.dump(2);
  EXPECT_EQ(j["effects"][0]["name"], "coulomb_friction");
  EXPECT_EQ(j["effects"][0]["joint"], "knee");
  EXPECT_NEAR(j["effects"][0]["value"].get<double>(), truth.effects[0].value, 0.15 * truth.effects[0].value);
  EXPECT_GE(j["joints"]["knee"]["gain_pct"].get<double>(), 50.0);
  EXPECT_EQ(j["validation"]["holdout_fraction"].get<double>(), 0.3);
  EXPECT_TRUE(j["unexplained"].is_array());
  const std::string html = testing::ReadText(d + "/out/report.html");
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("spectrum"), std::string::npos);
  // extended.yaml is a model file every command loads: predict runs the extended twin.
  r = RunExotwin("predict --params " + d + "/out/extended.yaml --measured " + d + "/data.csv --out " +
                 d + "/pred.csv");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadModelFile(d + "/out/extended.yaml").effects.size(), 1u);
}

// A one-joint device through the commands (DESIGN.md "One-joint devices"): generate a HAL-3 knee
// record with a hidden friction, predict writes t,tau_knee, diagnose names the friction at the knee
// alone and writes a one-joint extended.yaml that predict loads, identify fits I, mgl, R, C (the
// record's truth: the device's plus the operator's link and R + the hidden viscous friction).
TEST(DiagnoseCli, OneJointDeviceThroughGeneratePredictDiagnoseIdentify) {
  const testing::ScopedTempDir tmp("diag1j");
  const std::string d = tmp.path();
  const std::string hal = std::string(EXOTWIN_SOURCE_DIR) + "/examples/hal3_knee.yaml";
  auto r = RunExotwin("generate --params " + hal + " --seed 4 --effect viscous_friction --duration 20 --rate 500 --out " +
                      d + "/knee.csv --truth " + d + "/truth.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LegParams truth = ReadModelFile(d + "/truth.yaml");
  ASSERT_TRUE(truth.one_joint);
  const Effect hidden = truth.effects.back();
  r = RunExotwin("predict --params " + hal + " --measured " + d + "/knee.csv --out " + d + "/pred.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(testing::ReadText(d + "/pred.csv").find("\nt,tau_knee\n"), std::string::npos);
  r = RunExotwin("diagnose --params " + hal + " --measured " + d + "/knee.csv --out " + d + "/out");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(testing::ReadText(d + "/out/diagnosis.json"));
  EXPECT_TRUE(j["one_joint"].get<bool>());
  EXPECT_FALSE(j["joints"].contains("hip"));
  ASSERT_EQ(j["effects"].size(), 1u) << j.dump(2);
  EXPECT_EQ(j["effects"][0]["name"], "viscous_friction");
  EXPECT_NEAR(j["effects"][0]["value"].get<double>(), hidden.value, 0.15 * hidden.value);
  const LegParams ext = ReadModelFile(d + "/out/extended.yaml");
  ASSERT_TRUE(ext.one_joint);
  EXPECT_EQ(ext.one_joint->R, truth.one_joint->R);  // R, C as the model file gave them, the effect after
  ASSERT_EQ(ext.effects.size(), ext.one_joint->device_effects + 1);
  r = RunExotwin("predict --params " + d + "/out/extended.yaml --measured " + d + "/knee.csv --out " + d + "/p2.csv");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunExotwin("identify --measured " + d + "/knee.csv --friction --out " + d + "/id.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LegParams id = ReadModelFile(d + "/id.yaml");
  ASSERT_TRUE(id.one_joint);
  const OneJointModel& m = *truth.one_joint;
  EXPECT_NEAR(id.one_joint->device.I, m.device.I + m.human->I, 0.02 * (m.device.I + m.human->I));
  EXPECT_NEAR(id.one_joint->device.mgl, m.device.mgl + m.human->mgl, 0.02 * (m.device.mgl + m.human->mgl));
  EXPECT_NEAR(id.one_joint->R, m.R + hidden.value, 0.1 * (m.R + hidden.value));
  EXPECT_NEAR(id.one_joint->C, m.C, 0.25 * m.C);
  // One-joint and two-joint records mixed: exit 2 naming the record.
  ASSERT_EQ(RunExotwin("generate --params " + kS1 + " --seed 4 --clean --duration 5 --rate 200 --out " + d + "/two.csv").exit_code, 0);
  r = RunExotwin("identify --measured " + d + "/knee.csv --measured " + d + "/two.csv --out " + d + "/bad.yaml");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("two.csv: a record with hip columns among one-joint records"), std::string::npos) << r.output;
}

TEST(DiagnoseCli, MuscleActivityExtensionRunsInPredict) {
  const testing::ScopedTempDir tmp("diagemg");
  const std::string d = tmp.path();
  ASSERT_EQ(RunExotwin("generate --params " + kS1 + " --seed 3 --effect muscle_activity --duration 30"
                       " --rate 500 --out " + d + "/data.csv").exit_code, 0);
  ASSERT_EQ(RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/data.csv --out " + d + "/o").exit_code, 0);
  const LegParams ext = ReadModelFile(d + "/o/extended.yaml");
  ASSERT_EQ(ext.effects.size(), 1u);
  EXPECT_EQ(ext.effects[0].name, "muscle_activity");
  const auto r = RunExotwin("predict --params " + d + "/o/extended.yaml --measured " + d + "/data.csv --out " + d + "/p.csv");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(DiagnoseCli, BadInputIsExitTwoNamingTheFile) {
  const testing::ScopedTempDir tmp("diagbad");
  const std::string d = tmp.path();
  WriteText(d + "/short.csv", "t,q_hip,q_knee,tau_hip,tau_knee\n0,0.1,-0.2,1,1\n0.001,0.1,-0.2,1,1\n");
  auto r = RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/short.csv --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("short.csv"), std::string::npos) << r.output;
  r = RunExotwin("generate --params " + kS1 + " --seed 1 --effect levitation --out " + d + "/x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = RunExotwin("generate --params " + kS1 + " --seed 1 --duration -3 --out " + d + "/x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// Several records of one device; records of another device (other columns, another time unit), a bad
// --cutoff or --max-effects exit 2 naming the file or option, and nothing is written to --out.
TEST(DiagnoseCli, SeveralRecordsOfOneDeviceAndRecordsOfAnother) {
  const testing::ScopedTempDir tmp("diagmulti");
  const std::string d = tmp.path();
  // One device: the second record's truth is the first's (its hidden friction), another motion.
  ASSERT_EQ(RunExotwin("generate --params " + kS1 + " --seed 1 --effect coulomb_friction --joint knee"
                       " --duration 20 --rate 500 --out " + d + "/rec1.csv --truth " + d + "/truth.yaml").exit_code, 0);
  ASSERT_EQ(RunExotwin("generate --params " + d + "/truth.yaml --seed 2 --effects 0 --duration 20 --rate 500 --out " +
                       d + "/rec2.csv").exit_code, 0);
  const auto ok = RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/rec1.csv --measured " + d +
                             "/rec2.csv --out " + d + "/both");
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_NE(ok.output.find("whole records left out"), std::string::npos) << ok.output;
  const auto j = nlohmann::json::parse(testing::ReadText(d + "/both/diagnosis.json"));
  ASSERT_EQ(j["records"].size(), 2u);
  EXPECT_TRUE(j["validation"]["leave_one_record_out"].get<bool>());
  EXPECT_GT(j["left_out"]["knee"]["gain_pct"].get<double>(), 50.0);
  EXPECT_GT(j["records"][1]["left_out"]["knee"]["gain_pct"].get<double>(), 50.0);
  // Another device: the EMG columns dropped; the same record in milliseconds.
  const CsvTable t = ReadCsv(d + "/rec2.csv");
  std::vector<double> ms = t.columns[t.Find("t")];
  for (double& v : ms) v *= 1e3;
  const std::vector<const std::vector<double>*> five = {&t.columns[t.Find("t")], &t.columns[t.Find("q_hip")],
                                                        &t.columns[t.Find("q_knee")], &t.columns[t.Find("tau_hip")],
                                                        &t.columns[t.Find("tau_knee")]};
  WriteCsv(d + "/noemg.csv", {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"}, five);
  std::vector<const std::vector<double>*> in_ms = five;
  in_ms[0] = &ms;
  std::vector<std::string> names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  std::vector<const std::vector<double>*> cols = in_ms;
  for (size_t c = 0; c < t.names.size(); ++c)
    if (t.names[c].rfind("emg_", 0) == 0) names.push_back(t.names[c]), cols.push_back(&t.columns[c]);
  WriteCsv(d + "/ms.csv", names, cols);
  for (const char* other : {"noemg.csv", "ms.csv"}) {
    const auto r = RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/rec1.csv --measured " + d + "/" +
                              other + " --out " + d + "/o_" + other);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(other), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("expected records of one device"), std::string::npos) << r.output;
    EXPECT_FALSE(std::ifstream(d + "/o_" + other + "/diagnosis.json").good()) << other;
  }
  for (const char* opt : {"--cutoff slow", "--max-effects 9"}) {
    const auto r = RunExotwin("diagnose --params " + kS1 + " --measured " + d + "/rec1.csv --out " + d + "/o " + opt);
    EXPECT_EQ(r.exit_code, 2) << opt << ": " << r.output;
  }
}

// Beyond the leg: a planar two-joint arm-like chain, no human, other length and masses.
TEST(DiagnoseOtherChain, FindsEffectsOnAChainThatIsNotTheLeg) {
  const LegParams chain = ParseModelYaml(
      "L1: 0.62\nexo: {J1: 2.6, J2: 0.42, X1: 2.4, X2: 0.85, Y1: 0.05, Y2: -0.04}\n"
      "passive: none\neffects: []\n", "chain");
  int ok = 0;
  const char* names[] = {"viscous_friction", "sensor_offset", "series_compliance", "gravity_error"};
  for (int s = 0; s < 4; ++s) {
    GenerateOptions g;
    g.seed = 700 + s, g.duration = 30, g.rate = 500, g.allowed = {names[s]};
    const GeneratedData data = GenerateMeasured(chain, g);
    const Diagnosis d = Diagnose(chain, data.data);
    const Effect& t = data.truth.effects[0];
    ASSERT_EQ(d.effects.size(), 1u) << names[s];
    EXPECT_EQ(d.effects[0].effect.name, t.name);
    EXPECT_EQ(d.effects[0].effect.joint, t.joint);
    EXPECT_NEAR(d.effects[0].effect.value, t.value, 0.15 * std::abs(t.value)) << names[s];
    EXPECT_GE(d.joints[t.joint == "hip" ? 0 : 1].gain_pct, 50.0) << names[s];
    ++ok;
  }
  EXPECT_EQ(ok, 4);
  GenerateOptions g;
  g.seed = 800, g.duration = 30, g.rate = 500, g.effects = 0;
  EXPECT_TRUE(Diagnose(chain, GenerateMeasured(chain, g).data).effects.empty());
}

}  // namespace
}  // namespace exotwin
