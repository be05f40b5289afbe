// `exotwin emg-fit` and `exotwin emg-predict` through the command line (DESIGN.md contract): outputs,
// exit codes, and bad input that must exit 2 naming the file, line or channel.
#include <gtest/gtest.h>

#include <memory>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "formats/csv_table.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::ReadText;
using testing::RunExotwin;
using testing::WriteText;

constexpr int kRows = 2000;  // 20 s at 100 Hz

double Env(int c, double t) {
  const double s = std::sin(2 * M_PI * (0.8 + 0.17 * c) * t + c) + 0.4 * std::sin(2 * M_PI * 0.11 * (c + 1) * t);
  return 0.02 + 0.25 * std::max(0.0, s) * std::max(0.0, s);
}
double Hip(double t) { return 20 * std::sin(2 * M_PI * 0.9 * t) + 5; }        // deg
double Knee(double t) { return -35 - 25 * std::sin(2 * M_PI * 0.9 * t + 1); }  // deg

// emgFilt.sto as CEINMS writes it (no version line, trailing tab on every line).
std::string EmgSto(double t0 = 0, const std::string& bad_value = "", int bad_row = -1) {
  std::ostringstream o;
  o << "Normalized EMG Linear Envelopes\nnRows=" << kRows << "\nnColumns=6\n\nendheader\n"
    << "time\t  rect_fem_r\t vas_lat_r\t semimem_r\t med_gas_r\t soleus_r\t\n";
  for (int i = 0; i < kRows; ++i) {
    const double t = t0 + 0.01 * i;
    o << t;
    for (int c = 0; c < 5; ++c) o << "\t  " << (i == bad_row && c == 1 ? bad_value : std::to_string(Env(c, t)));
    o << "\t\n";
  }
  return o.str();
}

std::string IkSto(bool in_degrees_line = true) {
  std::ostringstream o;
  o << "Coordinates\nversion=1\nnRows=" << kRows << "\nnColumns=3\n" << (in_degrees_line ? "inDegrees=yes\n" : "")
    << "endheader\ntime\thip_flexion_r\tknee_angle_r\n";
  for (int i = 0; i < kRows; ++i) o << 0.01 * i << "\t" << Hip(0.01 * i) << "\t" << Knee(0.01 * i) << "\n";
  return o.str();
}

std::string IdSto(int drop_value_row = -1) {
  std::ostringstream o;
  o << "Inverse Dynamics Generalized Forces\nversion=1\nnRows=" << kRows
    << "\nnColumns=3\ninDegrees=no\nendheader\ntime\thip_flexion_r_moment\tknee_angle_r_moment\n";
  for (int i = 0; i < kRows; ++i) {
    const double t = 0.01 * i;
    const double hip = 50 * Env(0, t) - 60 * Env(2, t) - 0.2 * Hip(t) + 3 + 0.5 * std::sin(37.0 * i);
    const double knee = 80 * Env(1, t) + 20 * Env(0, t) - 30 * Env(2, t) - 40 * Env(3, t) + 0.1 * Knee(t) +
                        0.5 * std::cos(41.0 * i);
    o << t << "\t" << hip;
    if (i != drop_value_row) o << "\t" << knee;
    o << "\n";
  }
  return o.str();
}

// A storage file's trial played twice as fast (time halved), the value columns `doubled` (1-based
// after time) doubled.
std::string PlayedFaster(const std::string& text, const std::vector<int>& doubled) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  bool body = false;
  while (std::getline(in, line)) {
    if (body && !line.empty()) {
      std::istringstream f(line);
      std::vector<double> v;
      for (double x; f >> x;) v.push_back(x);
      v[0] /= 2;
      for (int c : doubled) v[static_cast<size_t>(c)] *= 2;
      for (size_t i = 0; i < v.size(); ++i) out << (i ? "\t" : "") << v[i];
      out << "\n";
      continue;
    }
    body |= line.rfind("time", 0) == 0;
    out << line << "\n";
  }
  return out.str();
}

class EmgCli : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<testing::ScopedTempDir>("emgcli");
    dir_ = tmp_->path();
    WriteText(dir_ + "/emg.sto", EmgSto());
    WriteText(dir_ + "/ik.sto", IkSto());
    WriteText(dir_ + "/id.sto", IdSto());
  }
  std::string Files(const std::string& emg = "emg.sto", const std::string& ik = "ik.sto",
                    const std::string& id = "id.sto") {
    return " --emg " + dir_ + "/" + emg + " --kinematics " + dir_ + "/" + ik + " --moments " + dir_ + "/" + id;
  }
  testing::RunResult Fit(const std::string& extra = "") {
    return RunExotwin("emg-fit" + Files() + " --out " + dir_ + "/model.yaml " + extra);
  }
  void ExpectBadInput(const testing::RunResult& r, const std::vector<std::string>& pieces) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    for (const auto& p : pieces) EXPECT_NE(r.output.find(p), std::string::npos) << "'" << p << "' not in: " << r.output;
  }
  std::unique_ptr<testing::ScopedTempDir> tmp_;
  std::string dir_;
};

TEST_F(EmgCli, FitWritesEveryParameterWithUnitAndUncertainty) {
  const auto r = Fit("--report " + dir_ + "/rep");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string y = ReadText(dir_ + "/model.yaml");
  for (const char* s : {"term: alpha, channel: rect_fem_r", "term: beta", "term: gamma", "term: offset", "se:",
                        "unit: \"N m s/rad\"", "missing_channels: [GMAX]"})
    EXPECT_NE(y.find(s), std::string::npos) << s << " not in:\n" << y;
  EXPECT_EQ(y.find("soleus_r"), std::string::npos);  // the soleus spans neither hip nor knee
  EXPECT_NE(r.output.find("soleus_r"), std::string::npos) << "unused channels are reported: " << r.output;
  EXPECT_NE(r.output.find("GMAX"), std::string::npos) << "the missing gluteus is reported: " << r.output;
  // ... and synthesized from the recorded excitations in the musculoskeletal form, said and written.
  EXPECT_NE(r.output.find("the missing GMAX synthesized from the recorded excitations"), std::string::npos) << r.output;
  EXPECT_NE(y.find("synthesized: true"), std::string::npos);
  EXPECT_NE(ReadText(dir_ + "/rep/report.html").find("GMAX from rect_fem_r"), std::string::npos);
  const std::string j = ReadText(dir_ + "/rep/diagnosis.json");
  for (const char* s : {"\"effects\"", "\"joints\"", "\"rmse_before\"", "\"gain_pct\"", "\"selection\"", "\"steps\""})
    EXPECT_NE(j.find(s), std::string::npos) << s;
  EXPECT_NE(ReadText(dir_ + "/rep/report.html").find("<svg"), std::string::npos);
}

TEST_F(EmgCli, PredictWritesContractColumnsAndPrintsR2) {
  ASSERT_EQ(Fit("--linear").exit_code, 0);
  const auto r = RunExotwin("emg-predict --model " + dir_ + "/model.yaml --emg " + dir_ + "/emg.sto --kinematics " +
                            dir_ + "/ik.sto --moments " + dir_ + "/id.sto --out " + dir_ + "/pred.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("hip: R^2 0.9"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("knee: R^2 0.9"), std::string::npos) << r.output;
  // The calibration's own recording: nothing outside its range.
  EXPECT_NE(r.output.find("extrapolation: share of samples outside the calibration's range"), std::string::npos);
  for (const char* what : {"envelope vas_lat_r", "envelope med_gas_r", "hip angle", "knee velocity"}) {
    char line[96];
    std::snprintf(line, sizeof line, "  %-28s    0.0 %%", what);
    EXPECT_NE(r.output.find(line), std::string::npos) << line << " not in: " << r.output;
  }
  EXPECT_EQ(r.output.find("warning: "), std::string::npos) << r.output;
  const CsvTable t = ReadCsv(dir_ + "/pred.csv");
  ASSERT_EQ(t.names, (std::vector<std::string>{"t", "tau_hip", "tau_knee"}));
  EXPECT_EQ(t.rows(), static_cast<size_t>(kRows));
  // Without moments: the estimate only.
  const auto r2 = RunExotwin("emg-predict --model " + dir_ + "/model.yaml --emg " + dir_ + "/emg.sto --kinematics " +
                             dir_ + "/ik.sto --out " + dir_ + "/pred2.csv");
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  EXPECT_EQ(r2.output.find("R^2"), std::string::npos);
}

TEST_F(EmgCli, PredictReportsExtrapolationPerChannelAndJoint) {
  ASSERT_EQ(Fit("--linear").exit_code, 0);
  // The same trial played twice as fast (velocities doubled) with the rectus femoris' envelope
  // doubled: its samples above the calibrated peak, and the velocities beyond theirs, are counted.
  std::string emg = EmgSto(), ik = IkSto();
  WriteText(dir_ + "/fast_emg.sto", PlayedFaster(emg, {1}));
  WriteText(dir_ + "/fast_ik.sto", PlayedFaster(ik, {}));
  const auto r = RunExotwin("emg-predict --model " + dir_ + "/model.yaml --emg " + dir_ + "/fast_emg.sto --kinematics " +
                            dir_ + "/fast_ik.sto --out " + dir_ + "/pred.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Share of the doubled rect_fem_r envelope above its calibrated peak, counted here.
  double peak = 0, above = 0;
  for (int i = 0; i < kRows; ++i) peak = std::max(peak, Env(0, 0.01 * i));
  for (int i = 0; i < kRows; ++i) above += 2 * Env(0, 0.01 * i) > peak;
  char expect[96];
  std::snprintf(expect, sizeof expect, "  %-28s %6.1f %%", "envelope rect_fem_r", 100 * above / kRows);
  EXPECT_GT(above, 0.05 * kRows);
  EXPECT_NE(r.output.find(expect), std::string::npos) << expect << " not in: " << r.output;
  EXPECT_NE(r.output.find("warning: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("of the samples of envelope rect_fem_r lie outside"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("of the samples of knee velocity lie outside"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("of the samples of knee angle"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("of the samples of envelope vas_lat_r"), std::string::npos) << r.output;
}

// Another gait (issue 42): emg-fit keeps the papers' form (HJ15 eq. 26) beside the calibrated one, the
// very fit `--linear` writes; on a recording most of whose samples leave the calibration's range at a
// joint, emg-predict predicts that joint by it and says so; on the calibration's own recording the
// calibrated form predicts.
TEST_F(EmgCli, AnotherGaitIsPredictedByThePapersFormAndSaysSo) {
  ASSERT_EQ(Fit().exit_code, 0);
  ASSERT_EQ(RunExotwin("emg-fit" + Files() + " --linear --out " + dir_ + "/linear.yaml").exit_code, 0);
  // The papers_form block of the full model is the --linear model's parameters block, line for line.
  auto block = [](const std::string& text, const std::string& key) {
    const size_t a = text.find("\n" + key + ":\n");
    if (a == std::string::npos) return std::string();
    size_t b = a + key.size() + 3;
    while (b < text.size() && text[b] == ' ') b = text.find('\n', b) + 1;
    return text.substr(a + key.size() + 3, b - (a + key.size() + 3));
  };
  const std::string papers = block(ReadText(dir_ + "/model.yaml"), "papers_form");
  ASSERT_FALSE(papers.empty());
  EXPECT_EQ(papers, block(ReadText(dir_ + "/linear.yaml"), "parameters"));
  // The trial twice as fast with every envelope doubled: most samples outside at both joints.
  WriteText(dir_ + "/fast_emg.sto", PlayedFaster(EmgSto(), {1, 2, 3, 4, 5}));
  WriteText(dir_ + "/fast_ik.sto", PlayedFaster(IkSto(), {}));
  auto predict = [&](const std::string& model, const std::string& emg, const std::string& ik, const std::string& out) {
    return RunExotwin("emg-predict --model " + dir_ + "/" + model + " --emg " + dir_ + "/" + emg + " --kinematics " +
                      dir_ + "/" + ik + " --out " + dir_ + "/" + out);
  };
  const auto r = predict("model.yaml", "fast_emg.sto", "fast_ik.sto", "fast.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* j : {"hip", "knee"}) {
    const std::string said = std::string(j) + ": ";
    const size_t at = r.output.find(said, r.output.find("forms:"));
    ASSERT_NE(at, std::string::npos) << r.output;
    EXPECT_NE(r.output.find("another gait than the calibrated one (above 50 %): predicted by the papers' form", at),
              std::string::npos) << r.output;
    EXPECT_NE(r.output.find("warning: at the " + std::string(j)), std::string::npos) << r.output;
  }
  ASSERT_EQ(predict("linear.yaml", "fast_emg.sto", "fast_ik.sto", "fast_linear.csv").exit_code, 0);
  const CsvTable a = ReadCsv(dir_ + "/fast.csv"), b = ReadCsv(dir_ + "/fast_linear.csv");
  ASSERT_EQ(a.rows(), b.rows());
  for (size_t c = 1; c < 3; ++c)
    for (size_t i = 0; i < a.rows(); ++i) ASSERT_EQ(a.columns[c][i], b.columns[c][i]) << c << " " << i;
  // The calibration's own trial: the calibrated form.
  const auto own = predict("model.yaml", "emg.sto", "ik.sto", "own.csv");
  ASSERT_EQ(own.exit_code, 0) << own.output;
  EXPECT_NE(own.output.find("hip: 0.0 % of the samples outside the calibration's range"), std::string::npos) << own.output;
  EXPECT_NE(own.output.find("the calibrated form predicts"), std::string::npos) << own.output;
  EXPECT_EQ(own.output.find("another gait"), std::string::npos) << own.output;
}

TEST_F(EmgCli, SeveralRecordingsAreFoldsAndBlocksNeedTwo) {
  WriteText(dir_ + "/emg2.sto", EmgSto());
  const auto r = RunExotwin("emg-fit" + Files() + Files("emg2.sto") + " --out " + dir_ + "/m2.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cv = 2 recordings left out in turn"), std::string::npos) << r.output;
  EXPECT_NE(ReadText(dir_ + "/m2.yaml").find("validation: \"each recording left out in turn\""), std::string::npos);
  ExpectBadInput(Fit("--blocks 1"), {"--blocks 1", "at least 2"});
}

TEST_F(EmgCli, MissingEndheader) {
  std::string s = EmgSto();
  s.erase(s.find("endheader\n"), 10);
  WriteText(dir_ + "/bad.sto", s);
  ExpectBadInput(RunExotwin("emg-fit" + Files("bad.sto") + " --out " + dir_ + "/m.yaml"), {"bad.sto", "endheader"});
}

TEST_F(EmgCli, RowWithTooFewValues) {
  WriteText(dir_ + "/bad.sto", IdSto(100));
  ExpectBadInput(RunExotwin("emg-fit" + Files("emg.sto", "ik.sto", "bad.sto") + " --out " + dir_ + "/m.yaml"),
                 {"bad.sto", "line 108", "2 values, 3 column names"});
}

TEST_F(EmgCli, TimeBasesThatDoNotOverlap) {
  WriteText(dir_ + "/late.sto", EmgSto(100.0));
  ExpectBadInput(RunExotwin("emg-fit" + Files("late.sto") + " --out " + dir_ + "/m.yaml"), {"late.sto", "time bases"});
}

TEST_F(EmgCli, MapNamingAMissingChannel) {
  WriteText(dir_ + "/map.yaml", "muscles:\n  VM: [vas_lat_r, vas_med_r]\n  RF: [rect_fem_r]\n");
  ExpectBadInput(Fit("--map " + dir_ + "/map.yaml"), {"map.yaml", "vas_med_r"});
}

TEST_F(EmgCli, NegativeAndNanEnvelopes) {
  WriteText(dir_ + "/neg.sto", EmgSto(0, "-0.5", 10));
  ExpectBadInput(RunExotwin("emg-fit" + Files("neg.sto") + " --out " + dir_ + "/m.yaml"),
                 {"neg.sto", "line 17", "vas_lat_r"});
  WriteText(dir_ + "/nan.sto", EmgSto(0, "nan", 20));
  ExpectBadInput(RunExotwin("emg-fit" + Files("nan.sto") + " --out " + dir_ + "/m.yaml"),
                 {"nan.sto", "line 27", "vas_lat_r"});
}

TEST_F(EmgCli, AngleUnitNotStated) {
  WriteText(dir_ + "/ik_nounit.sto", IkSto(false));
  ExpectBadInput(RunExotwin("emg-fit" + Files("emg.sto", "ik_nounit.sto") + " --out " + dir_ + "/m.yaml"),
                 {"ik_nounit.sto", "inDegrees"});
}

TEST_F(EmgCli, RecordingsNotInStep) {
  ExpectBadInput(RunExotwin("emg-fit" + Files() + " --emg " + dir_ + "/emg.sto --out " + dir_ + "/m.yaml"),
                 {"--emg", "--kinematics"});
}

TEST_F(EmgCli, PapersFormWithAnotherTerm) {
  ASSERT_EQ(Fit().exit_code, 0);
  std::string y = ReadText(dir_ + "/model.yaml");
  const std::string key = "papers_form:\n  hip:\n";
  const size_t at = y.find(key);
  ASSERT_NE(at, std::string::npos) << y;
  y.insert(at + key.size(), "    - {term: passive_scale, value: 1, se: 0, unit: \"1\"}\n");
  WriteText(dir_ + "/bad.yaml", y);
  ExpectBadInput(RunExotwin("emg-predict --model " + dir_ + "/bad.yaml --emg " + dir_ + "/emg.sto --kinematics " +
                            dir_ + "/ik.sto --out " + dir_ + "/p.csv"),
                 {"bad.yaml", "papers_form.hip", "passive_scale"});
}

TEST_F(EmgCli, BadModelFile) {
  WriteText(dir_ + "/bad.yaml", "model: something_else\n");
  ExpectBadInput(RunExotwin("emg-predict --model " + dir_ + "/bad.yaml --emg " + dir_ + "/emg.sto --kinematics " +
                            dir_ + "/ik.sto --out " + dir_ + "/p.csv"),
                 {"bad.yaml", "model"});
}

}  // namespace
}  // namespace exotwin
