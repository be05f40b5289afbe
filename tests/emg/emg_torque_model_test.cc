// The EMG-driven joint-moment model (emg/emg_torque_model.h) and its discrepancy loop
// (emg/emg_diagnose.h) on synthetic recordings where the truth is known: the linear form's
// alpha, beta, gamma are recovered; a delay or an activation nonlinearity hidden in the data is named
// and its value recovered; the model file round-trips.
#include "emg/emg_torque_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "emg/emg_diagnose.h"
#include "core/error.h"
#include "core/rng.h"
#include "sim/muscles.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

struct Truth {
  double alpha_hip[3] = {60, -40, -25};            // rect_fem_r, semimem_r, bifemlh_r at the hip
  double alpha_knee[5] = {70, 30, -35, -20, -30};  // vas_lat_r, rect_fem_r, semimem_r, bifemlh_r, med_gas_r
  double beta[2] = {-20, 15}, gamma[2] = {-2, 1.5}, offset[2] = {3, -2};
  double vm_delay = 0;  // s, hidden in the knee's vastus channel
  double a_shape = 0;   // hidden activation nonlinearity (all channels)
  double noise = 1.0;   // N m
};

// A 60 s recording at 100 Hz: gait-like envelopes (bursts at different phases and rates so that no
// two channels are collinear), hip and knee angles, and moments made by the model with `truth`.
EmgRecording Synthetic(const Truth& tr, uint64_t seed = 1) {
  EmgRecording r;
  r.source = "synthetic";
  const size_t n = 6000;
  const char* ch[] = {"vas_lat_r", "rect_fem_r", "semimem_r", "bifemlh_r", "med_gas_r"};
  const Muscle mu[] = {Muscle::kVM, Muscle::kRF, Muscle::kST, Muscle::kST, Muscle::kGAS};
  const double f[] = {0.93, 1.21, 0.77, 1.07, 1.37}, ph[] = {0.0, 1.3, 2.1, 3.7, 5.0};
  NormalRng<NormalPolar> rng(seed);
  for (size_t i = 0; i < n; ++i) r.t.push_back(0.01 * static_cast<double>(i));
  for (int c = 0; c < 5; ++c) {
    r.channels.push_back(ch[c]);
    r.muscle.push_back(mu[c]);
    std::vector<double> e(n);
    for (size_t i = 0; i < n; ++i) {
      const double t = r.t[i];
      const double s = std::sin(2 * M_PI * f[c] * t + ph[c]) + 0.4 * std::sin(2 * M_PI * 0.13 * (c + 1) * t);
      e[i] = 0.02 + 0.5 * std::pow(std::max(0.0, s), 2) / 1.96;
    }
    r.e.push_back(e);
  }
  r.missing = {"GMAX"};
  for (size_t i = 0; i < n; ++i) {
    const double t = r.t[i], w = 2 * M_PI * 0.9;
    r.q[0].push_back(0.3 * std::sin(w * t) + 0.1);
    r.qd[0].push_back(0.3 * w * std::cos(w * t));
    r.q[1].push_back(-0.6 - 0.4 * std::sin(w * t + 1));
    r.qd[1].push_back(-0.4 * w * std::cos(w * t + 1));
  }
  // Activation of each channel with the hidden delay (VM) and shape.
  std::vector<std::vector<double>> a(5, std::vector<double>(n));
  for (int c = 0; c < 5; ++c)
    for (size_t i = 0; i < n; ++i) {
      const double d = c == 0 ? tr.vm_delay : 0.0;
      const double tq = r.t[i] - d;
      const double x = std::max(0.0, tq / 0.01);
      const size_t k = std::min(n - 2, static_cast<size_t>(x));
      const double fr = std::min(1.0, x - static_cast<double>(k));
      const double u = r.e[c][k] * (1 - fr) + r.e[c][k + 1] * fr;
      a[c][i] = ActivationShape(u, tr.a_shape);
    }
  for (int j = 0; j < 2; ++j) r.tau[j].resize(n);
  for (size_t i = 0; i < n; ++i) {
    r.tau[0][i] = tr.alpha_hip[0] * a[1][i] + tr.alpha_hip[1] * a[2][i] + tr.alpha_hip[2] * a[3][i] +
                  tr.beta[0] * r.q[0][i] + tr.gamma[0] * r.qd[0][i] + tr.offset[0] + tr.noise * rng.Normal();
    r.tau[1][i] = tr.alpha_knee[0] * a[0][i] + tr.alpha_knee[1] * a[1][i] + tr.alpha_knee[2] * a[2][i] +
                  tr.alpha_knee[3] * a[3][i] + tr.alpha_knee[4] * a[4][i] + tr.beta[1] * r.q[1][i] +
                  tr.gamma[1] * r.qd[1][i] + tr.offset[1] + tr.noise * rng.Normal();
  }
  return r;
}

const EmgTerm& Term(const EmgTorqueModel& m, int joint, TermKind k, const std::string& ch = "") {
  for (const EmgTerm& t : m.terms)
    if (t.joint == joint && t.kind == k && t.channel == ch && !t.proxy) return t;
  throw std::runtime_error("no term");
}

TEST(EmgTorqueModel, ActivationShapeOfLloydAndBesier) {
  EXPECT_DOUBLE_EQ(ActivationShape(0.3, 0), 0.3);
  EXPECT_NEAR(ActivationShape(1.0, -2), 1.0, 1e-15);
  EXPECT_NEAR(ActivationShape(0.0, -2), 0.0, 1e-15);
  EXPECT_NEAR(ActivationShape(0.5, -2), std::expm1(-1.0) / std::expm1(-2.0), 1e-15);
  EXPECT_GT(ActivationShape(0.2, -2), 0.2);  // A < 0: concave, rises fast at low excitation
}

TEST(EmgTorqueModel, LinearFormRecoversTheTruth) {
  const Truth tr;
  const EmgRecording r = Synthetic(tr);
  const EmgTorqueModel m = FitEmgModel(EmgModelSpec{}, {&r});
  const char* hip[] = {"rect_fem_r", "semimem_r", "bifemlh_r"};
  const char* knee[] = {"vas_lat_r", "rect_fem_r", "semimem_r", "bifemlh_r", "med_gas_r"};
  for (int i = 0; i < 3; ++i) {
    const EmgTerm& t = Term(m, 0, TermKind::kAlpha, hip[i]);
    EXPECT_NEAR(t.value, tr.alpha_hip[i], 4 * t.se) << hip[i];
    EXPECT_NEAR(t.value, tr.alpha_hip[i], 0.05 * std::abs(tr.alpha_hip[i])) << hip[i];
  }
  for (int i = 0; i < 5; ++i) {
    const EmgTerm& t = Term(m, 1, TermKind::kAlpha, knee[i]);
    EXPECT_NEAR(t.value, tr.alpha_knee[i], 4 * t.se) << knee[i];
    EXPECT_NEAR(t.value, tr.alpha_knee[i], 0.05 * std::abs(tr.alpha_knee[i])) << knee[i];
  }
  for (int j = 0; j < 2; ++j) {
    const EmgTerm& b = Term(m, j, TermKind::kBeta);
    const EmgTerm& g = Term(m, j, TermKind::kGamma);
    EXPECT_NEAR(b.value, tr.beta[j], std::max(4 * b.se, 1e-9));
    EXPECT_NEAR(g.value, tr.gamma[j], std::max(4 * g.se, 1e-9));
    EXPECT_NEAR(b.value, tr.beta[j], 0.05 * std::abs(tr.beta[j]));
    EXPECT_NEAR(g.value, tr.gamma[j], 0.05 * std::abs(tr.gamma[j]));
    EXPECT_GT(m.figures[j].r2_heldout, 0.95);
    EXPECT_EQ(b.Unit(), "N m/rad");
    EXPECT_EQ(g.Unit(), "N m s/rad");
  }
  EXPECT_EQ(Term(m, 0, TermKind::kAlpha, "rect_fem_r").Unit(), "N m");
  // The vastus does not span the hip: no hip term of it.
  for (const EmgTerm& t : m.terms) EXPECT_FALSE(t.joint == 0 && t.channel == "vas_lat_r");
}

TEST(EmgTorqueModel, LoopAddsNothingToTheLinearTruth) {
  const EmgRecording r = Synthetic(Truth{});
  const EmgDiagnosis d = DiagnoseEmg({&r});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  EXPECT_EQ(d.steps.size(), 1u) << d.steps.back().added;
}

TEST(EmgTorqueModel, HiddenDelayIsNamedAndRecovered) {
  Truth tr;
  tr.vm_delay = 0.06;
  const EmgRecording r = Synthetic(tr);
  const EmgDiagnosis d = DiagnoseEmg({&r});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  ASSERT_TRUE(d.calibration.spec.delay_s.count(Muscle::kVM));
  const double v = d.calibration.spec.delay_s.at(Muscle::kVM), se = d.calibration.spec.delay_se.at(Muscle::kVM);
  EXPECT_NEAR(v, 0.06, 0.006);
  EXPECT_LT(se, 0.01);
  EXPECT_EQ(d.calibration.spec.a_shape, 0.0);
  EXPECT_GT(d.steps.back().model.figures[1].r2_heldout, d.steps.front().model.figures[1].r2_heldout);
}

TEST(EmgTorqueModel, HiddenActivationNonlinearityIsNamedAndRecovered) {
  Truth tr;
  tr.a_shape = -2.0;
  const EmgRecording r = Synthetic(tr);
  const EmgDiagnosis d = DiagnoseEmg({&r});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  EXPECT_NEAR(d.calibration.spec.a_shape, -2.0, 0.3);
  EXPECT_TRUE(d.calibration.spec.delay_s.empty());
}

TEST(EmgTorqueModel, SeveralRecordingsAreLeftOutInTurn) {
  Truth tr;
  tr.vm_delay = 0.08;
  const EmgRecording a = Synthetic(tr, 1), b = Synthetic(tr, 2);
  const EmgDiagnosis d = DiagnoseEmg({&a, &b});
  EXPECT_TRUE(d.leave_one_out);
  ASSERT_TRUE(d.calibration.spec.delay_s.count(Muscle::kVM));
  EXPECT_NEAR(d.calibration.spec.delay_s.at(Muscle::kVM), 0.08, 0.006);
  bool scored = false;
  for (const auto& c : d.scores) scored |= c.added && c.left_out_gain_pct[1] > 50;
  EXPECT_TRUE(scored) << "the added delay pays on whole recordings left out";
}

TEST(EmgTorqueModel, ModelFileRoundTrips) {
  Truth tr;
  tr.vm_delay = 0.05;
  const EmgRecording r = Synthetic(tr);
  EmgModelSpec s;
  s.delay_s[Muscle::kVM] = 0.05;
  s.delay_se[Muscle::kVM] = 0.002;
  s.passive[0] = true;
  s.moment_arm[1] = true;
  const EmgTorqueModel m = FitEmgModel(s, {&r});
  const testing::ScopedTempDir dir_tmp("emgmodel");
  const std::string dir = dir_tmp.path();
  const std::string path = dir + "/m.yaml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    const std::string text = EmgModelYaml(m, {"test"});
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
  }
  const EmgTorqueModel back = ReadEmgModel(path);
  ASSERT_EQ(back.terms.size(), m.terms.size());
  EXPECT_EQ(back.spec.Delay(Muscle::kVM), 0.05);
  EXPECT_TRUE(back.spec.passive[0]);
  EXPECT_TRUE(back.spec.moment_arm[1]);
  for (int j = 0; j < 2; ++j) {
    const std::vector<double> a = PredictMoment(m, r, j), b = PredictMoment(back, r, j);
    for (size_t i = 0; i < a.size(); i += 97) EXPECT_NEAR(a[i], b[i], 1e-6 * (1 + std::abs(a[i])));
  }
}

TEST(EmgTorqueModel, SpikeLimit) {
  std::vector<double> x = {0, 1, -1, 0.5, -0.5, 0, 1, -1, 0.2, 100};
  const std::vector<size_t> in = WithinSpikeLimit(x, 0, x.size());
  EXPECT_EQ(in.size(), 9u);
  EXPECT_EQ(in.back(), 8u);
}

}  // namespace
}  // namespace exotwin
