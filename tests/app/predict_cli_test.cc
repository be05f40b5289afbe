// `exotwin predict` through the command line: the contract of DESIGN.md, and bad input that must exit
// 2 with a message naming the place and what was expected (one test per case).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "formats/csv_table.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

constexpr const char* kModel = testing::kSubjectModelYaml;

std::string GoodCsv(int n = 200, double dt = 0.001) {
  std::ostringstream os;
  os << "t,q_hip,q_knee,tau_hip,tau_knee\n";
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    os << t << "," << 0.3 + 0.1 * std::sin(2 * t) << "," << -0.7 + 0.2 * std::sin(3 * t) << ",-20,-5\n";
  }
  return os.str();
}

class PredictCli : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteText(dir_ + "/model.yaml", kModel);
    WriteText(dir_ + "/data.csv", GoodCsv());
  }
  // Runs predict with a modified model and/or data file; returns the result.
  testing::RunResult Predict(const std::string& model, const std::string& data,
                             const std::string& extra = "") {
    WriteText(dir_ + "/m.yaml", model);
    WriteText(dir_ + "/d.csv", data);
    return RunExotwin("predict --params " + dir_ + "/m.yaml --measured " + dir_ + "/d.csv --out " +
                      dir_ + "/pred.csv " + extra);
  }
  void ExpectBadInput(const testing::RunResult& r, const std::string& must_contain) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(must_contain), std::string::npos)
        << "message should contain '" << must_contain << "': " << r.output;
  }
  const testing::ScopedTempDir tmp_{"predict"};
  const std::string dir_ = tmp_.path();
};

TEST_F(PredictCli, WritesPredictionWithContractColumns) {
  const auto r = RunExotwin("predict --params " + dir_ + "/model.yaml --measured " + dir_ +
                            "/data.csv --out " + dir_ + "/pred.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const CsvTable t = ReadCsv(dir_ + "/pred.csv");
  ASSERT_EQ(t.names, (std::vector<std::string>{"t", "tau_hip", "tau_knee"}));
  EXPECT_EQ(t.rows(), 200u);
}

// Issue 21: the same record as a spreadsheet or lab software writes it (byte-order mark, CRLF line
// ends, RFC 4180 quotes, a trailing comma on every line) predicts the same torques, to the byte.
TEST_F(PredictCli, SpreadsheetDialectsPredictAsThePlainFile) {
  const auto plain = Predict(kModel, GoodCsv());
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const std::string expected = testing::ReadText(dir_ + "/pred.csv");
  std::string dialect = "\xEF\xBB\xBF";  // UTF-8 byte-order mark
  std::istringstream in(GoodCsv());
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) dialect += "\"" + f + "\",";  // quoted; ends with ','
    dialect += "\r\n";
  }
  const auto r = Predict(kModel, dialect);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(testing::ReadText(dir_ + "/pred.csv"), expected);
}

TEST_F(PredictCli, MissingColumn) {
  ExpectBadInput(Predict(kModel, "t,q_hip,q_knee,tau_hip\n0,0,0,0\n"), "missing required column 'tau_knee'");
}
TEST_F(PredictCli, NonIncreasingTime) {
  std::string csv = GoodCsv();
  csv += "0.1,0.3,-0.7,-20,-5\n";
  ExpectBadInput(Predict(kModel, csv), "expected strictly increasing time");
}
TEST_F(PredictCli, NaNValue) {
  std::string csv = GoodCsv(50);
  csv += "0.5,nan,-0.7,-20,-5\n";
  ExpectBadInput(Predict(kModel, csv), "column 'q_hip': value is not finite");
}
TEST_F(PredictCli, TooFewSamples) { ExpectBadInput(Predict(kModel, GoodCsv(5)), "expected at least"); }
TEST_F(PredictCli, NotANumber) {
  ExpectBadInput(Predict(kModel, GoodCsv(30) + "0.9,abc,-0.7,-20,-5\n"), "'abc' is not a number");
}
TEST_F(PredictCli, WrongFieldCount) {
  ExpectBadInput(Predict(kModel, GoodCsv(30) + "0.9,0.2,-0.7\n"), "expected 5 fields");
}
TEST_F(PredictCli, EmptyCsv) { ExpectBadInput(Predict(kModel, ""), "file is empty"); }
TEST_F(PredictCli, UnknownYamlKey) {
  ExpectBadInput(Predict(std::string(kModel) + "colour: red\n", GoodCsv()), "colour: unknown key");
}
TEST_F(PredictCli, MissingYamlKey) {
  ExpectBadInput(Predict("L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15}\n", GoodCsv()),
                 "exo.Y2: missing");
}
TEST_F(PredictCli, WrongType) {
  ExpectBadInput(Predict("L1: long\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.1}\n",
                         GoodCsv()),
                 "L1: 'long' is not a number");
}
TEST_F(PredictCli, NegativeMass) {
  ExpectBadInput(
      Predict("L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16, m2: -2}\n",
              GoodCsv()),
      "exo.m2: mass must be > 0 kg");
}
TEST_F(PredictCli, InconsistentParameterSet) {
  // J1 = J2: no thigh inertia can be left for the lower leg's m2 L1^2 term.
  ExpectBadInput(Predict("L1: 0.41\nexo: {J1: 0.74, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n",
                         GoodCsv()),
                 "exo: lumped parameters have no physically consistent realization");
}
TEST_F(PredictCli, UnreadableMjcf) {
  WriteText(dir_ + "/bad.xml", "<mujoco><worldbody><body name='x'>");
  ExpectBadInput(Predict(kModel, GoodCsv(), "--mjcf " + dir_ + "/bad.xml"), "cannot load MJCF model");
}
TEST_F(PredictCli, MjcfWithoutExpectedBodies) {
  WriteText(dir_ + "/other.xml",
            "<mujoco><worldbody><body name='b'><joint type='hinge'/><geom size='0.1'/></body>"
            "</worldbody></mujoco>");
  ExpectBadInput(Predict(kModel, GoodCsv(), "--mjcf " + dir_ + "/other.xml"), "no body named 'exo_thigh'");
}
TEST_F(PredictCli, PassiveWithoutHuman) {
  ExpectBadInput(Predict("L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n"
                         "passive: riener1999\n",
                         GoodCsv()),
                 "passive: acts on the human only");
}
TEST_F(PredictCli, MalformedYaml) {
  ExpectBadInput(Predict("L1: [0.41\n", GoodCsv()), "malformed YAML");
}
TEST_F(PredictCli, MissingRequiredOption) {
  const auto r = RunExotwin("predict --params " + dir_ + "/model.yaml");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// --cutoff: the default is the paper's 20 Hz (the same file byte for byte); a number sets the
// derivative filter (named in the output's comment); a bad value exits 2 naming the option.
TEST_F(PredictCli, CutoffDefaultIsTwentyHertzAndAValueSetsTheFilter) {
  ASSERT_EQ(Predict(kModel, GoodCsv(2000)).exit_code, 0);
  const std::string def = testing::ReadText(dir_ + "/pred.csv");
  ASSERT_EQ(Predict(kModel, GoodCsv(2000), "--cutoff 20").exit_code, 0);
  EXPECT_EQ(testing::ReadText(dir_ + "/pred.csv"), def);
  ASSERT_EQ(Predict(kModel, GoodCsv(2000), "--cutoff 5").exit_code, 0);
  const std::string five = testing::ReadText(dir_ + "/pred.csv");
  EXPECT_NE(five.find("butterworth 5 Hz"), std::string::npos);
  EXPECT_NE(five, def);
  ExpectBadInput(Predict(kModel, GoodCsv(2000), "--cutoff fast"), "--cutoff");
  ExpectBadInput(Predict(kModel, GoodCsv(2000), "--cutoff 0"), "expected a cutoff in Hz");
}

// --cutoff auto on a real rig's record (examples/real_rig: 500 Hz, a coarse encoder) chooses a
// cutoff below 20 Hz, says why on stderr, and its prediction is closer to the measured torque than
// the 20 Hz one (the noise differentiation injects at 20 Hz outweighs what the filter takes).
TEST_F(PredictCli, CutoffAutoOnARealRigChoosesFromTheData) {
  const std::string ex = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/";
  const std::string base = "predict --params " + ex + "model.yaml --measured " + ex + "trajectory_11.csv --map " +
                           ex + "dfki_double_pendulum_A0.map.yaml --out ";
  const auto a = RunExotwin(base + dir_ + "/auto.csv --cutoff auto");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_NE(a.output.find("derivative cutoff"), std::string::npos) << a.output;
  ASSERT_EQ(RunExotwin(base + dir_ + "/p20.csv").exit_code, 0);
  const CsvTable pa = ReadCsv(dir_ + "/auto.csv"), p20 = ReadCsv(dir_ + "/p20.csv");
  const CsvTable m = ReadCsv(ex + "trajectory_11.csv");
  const auto& meas = m.columns[m.Find("tau_meas1")];
  ASSERT_EQ(pa.rows(), meas.size());
  double ea = 0, e20 = 0;
  for (size_t i = 500; i + 500 < meas.size(); ++i) {  // tau_hip = -tau_meas1 (the map)
    ea += std::pow(pa.columns[1][i] + meas[i], 2);
    e20 += std::pow(p20.columns[1][i] + meas[i], 2);
  }
  EXPECT_LT(ea, 0.7 * e20);
}

// Non-uniform sampling is resampled (and said on stderr); the prediction equals the one on the
// uniformly sampled signal at the common times within the derivative filter's accuracy.
TEST_F(PredictCli, NonUniformSamplingIsResampled) {
  std::ostringstream os;
  os << "t,q_hip,q_knee,tau_hip,tau_knee\n";
  double t = 0;
  for (int i = 0; i < 2000; ++i) {
    os << t << "," << 0.3 + 0.1 * std::sin(2 * t) << "," << -0.7 + 0.2 * std::sin(3 * t) << ",0,0\n";
    t += (i % 2) ? 0.0008 : 0.0012;
  }
  const auto r = Predict(kModel, os.str());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("non-uniformly"), std::string::npos);
  const CsvTable p = ReadCsv(dir_ + "/pred.csv");
  EXPECT_EQ(p.rows(), 2000u);
}

// A term's expression outside the grammar: exit 2 naming the file, the effect and the position.
TEST_F(PredictCli, BadTermExpressionNamesItsPosition) {
  std::string model = kModel;
  model.replace(model.find("effects: []"), std::string::npos,
                "effects:\n  - {name: term, joint: knee, value: 0.5, expr: \"abs(tau_R) * sgn(qd\"}\n");
  const auto r = Predict(model, GoodCsv());
  ExpectBadInput(r, "m.yaml");
  ExpectBadInput(r, "effects[0].expr");
  ExpectBadInput(r, "expected ')' at position 19");
}

// A term in the model file reaches predict: "1.0*sgn(qd)" gives coulomb_friction 1.0's torque.
TEST_F(PredictCli, TermSgnIsCoulomb) {
  std::string coulomb = kModel, term = kModel;
  coulomb.replace(coulomb.find("effects: []"), std::string::npos,
                  "effects:\n  - {name: coulomb_friction, joint: knee, value: 1.0}\n");
  term.replace(term.find("effects: []"), std::string::npos,
               "effects:\n  - {name: term, joint: knee, value: 1.0, unit: \"N m\", expr: \"sgn(qd)\"}\n");
  ASSERT_EQ(Predict(coulomb, GoodCsv()).exit_code, 0);
  const CsvTable a = ReadCsv(dir_ + "/pred.csv");
  ASSERT_EQ(Predict(term, GoodCsv()).exit_code, 0);
  const CsvTable b = ReadCsv(dir_ + "/pred.csv");
  ASSERT_EQ(a.rows(), b.rows());
  for (size_t c = 0; c < a.names.size(); ++c)
    for (size_t i = 0; i < a.rows(); ++i) ASSERT_NEAR(a.columns[c][i], b.columns[c][i], 1e-12) << a.names[c] << " " << i;
}

// generate --term hides a term; predict with the truth it writes gives the generated reading to the
// noise level (the record's derivatives are the filtered ones), the rigid twin misses the term.
TEST_F(PredictCli, GenerateTermThenPredictWithItGivesTheRecord) {
  const std::string model = dir_ + "/model.yaml", rec = dir_ + "/gen.csv", truth = dir_ + "/truth.yaml";
  const auto g = RunExotwin("generate --params " + model + " --seed 4 --out " + rec + " --truth " + truth +
                            " --joint knee --duration 8 --term \"(0.3 + 0.06 * abs(tau_R)) * sgn(qd)\" --value 1.0");
  ASSERT_EQ(g.exit_code, 0) << g.output;
  auto residual = [&](const std::string& params) {
    const auto r = RunExotwin("predict --params " + params + " --measured " + rec + " --out " + dir_ + "/p.csv");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const CsvTable m = ReadCsv(rec), p = ReadCsv(dir_ + "/p.csv");
    const std::vector<double>&a = m.columns[m.Find("tau_knee")], &b = p.columns[p.Find("tau_knee")];
    double s = 0;
    size_t n = 0;
    for (size_t i = 200; i + 200 < a.size(); ++i, ++n) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s / n);
  };
  const double with_term = residual(truth), rigid = residual(model);
  std::printf("knee residual RMS: with the term %.4f N m, rigid %.4f N m\n", with_term, rigid);
  EXPECT_LT(with_term, 0.05);  // sensor noise 0.02-0.04 N m, resolution 0.005 N m
  EXPECT_GT(rigid, 10 * with_term);
  const auto bad = RunExotwin("generate --params " + model + " --seed 4 --out " + rec +
                              " --joint knee --duration 3 --term \"abs(tau_R) * sgn(qd\" --value 1.0");
  ExpectBadInput(bad, "--term \"abs(tau_R) * sgn(qd\": expected ')' at position 19");
  ExpectBadInput(RunExotwin("generate --params " + model + " --seed 4 --out " + rec + " --joint knee --term q"),
                 "one --value per --term");
}

}  // namespace
}  // namespace exotwin
