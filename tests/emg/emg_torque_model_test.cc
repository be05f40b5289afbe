// The EMG-driven joint-moment model (emg/emg_torque_model.h) and its discrepancy loop
// (emg/emg_diagnose.h) on synthetic recordings where the truth is known: the linear form's
// alpha, beta, gamma are recovered; a delay or an activation nonlinearity hidden in the data is named
// and its value recovered; the model file round-trips.
#include "emg/emg_torque_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "emg/emg_diagnose.h"
#include "core/error.h"
#include "core/rng.h"
#include "formats/measured_data.h"
#include "sim/muscles.h"
#include "tests/emg/gait_trial.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

struct Truth {
  double alpha_hip[3] = {60, -40, -25};            // rect_fem_r, semimem_r, bifemlh_r at the hip
  double alpha_knee[5] = {70, 30, -35, -20, -30};  // vas_lat_r, rect_fem_r, semimem_r, bifemlh_r, med_gas_r
  double beta[2] = {-20, 15}, gamma[2] = {-2, 1.5}, offset[2] = {3, -2};
  double delay = 0;     // s, electromechanical delay hidden in every channel
  double a_shape = 0;   // hidden activation nonlinearity (all channels)
  double noise = 1.0;   // N m
};

// The moments of HJ15 eq. 26's linear form with `tr`'s alphas, beta, gamma and offset on the
// activations a (the recording's five channels), plus white noise of SD `noise` (N m), into r->tau.
void LinearLawMoments(const Truth& tr, const std::vector<std::vector<double>>& a, double noise,
                      NormalRng<NormalPolar>& rng, EmgRecording* r) {
  const size_t n = r->t.size();
  for (int j = 0; j < 2; ++j) r->tau[j].resize(n);
  for (size_t i = 0; i < n; ++i) {
    r->tau[0][i] = tr.alpha_hip[0] * a[1][i] + tr.alpha_hip[1] * a[2][i] + tr.alpha_hip[2] * a[3][i] +
                   tr.beta[0] * r->q[0][i] + tr.gamma[0] * r->qd[0][i] + tr.offset[0] + noise * rng.Normal();
    r->tau[1][i] = tr.alpha_knee[0] * a[0][i] + tr.alpha_knee[1] * a[1][i] + tr.alpha_knee[2] * a[2][i] +
                   tr.alpha_knee[3] * a[3][i] + tr.alpha_knee[4] * a[4][i] + tr.beta[1] * r->q[1][i] +
                   tr.gamma[1] * r->qd[1][i] + tr.offset[1] + noise * rng.Normal();
  }
}

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
      const double tq = r.t[i] - tr.delay;
      const double x = std::max(0.0, tq / 0.01);
      const size_t k = std::min(n - 2, static_cast<size_t>(x));
      const double fr = std::min(1.0, x - static_cast<double>(k));
      const double u = r.e[c][k] * (1 - fr) + r.e[c][k + 1] * fr;
      a[c][i] = ActivationShape(u, tr.a_shape);
    }
  LinearLawMoments(tr, a, tr.noise, rng, &r);
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
  tr.delay = 0.06;
  const EmgRecording r = Synthetic(tr);
  const EmgDiagnosis d = DiagnoseEmg({&r});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  const double v = d.calibration.spec.common_delay, se = d.calibration.spec.common_delay_se;
  EXPECT_NEAR(v, 0.06, 0.006);
  EXPECT_GT(se, 0.0);
  EXPECT_LT(se, 0.01);
  EXPECT_TRUE(d.calibration.spec.delay_s.empty()) << "one delay, common to every channel";
  EXPECT_EQ(d.calibration.spec.a_shape, 0.0);
  EXPECT_EQ(d.calibration.spec.twitch, 0.0);
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
  EXPECT_EQ(d.calibration.spec.common_delay, 0.0);
  EXPECT_EQ(d.calibration.spec.twitch, 0.0);
}

TEST(EmgTorqueModel, SeveralRecordingsAreLeftOutInTurn) {
  Truth tr;
  tr.delay = 0.08;
  const EmgRecording a = Synthetic(tr, 1), b = Synthetic(tr, 2);
  const EmgDiagnosis d = DiagnoseEmg({&a, &b});
  EXPECT_TRUE(d.folds_are_recordings);
  EXPECT_EQ(d.folds, 2);
  EXPECT_NEAR(d.calibration.spec.common_delay, 0.08, 0.006);
  bool scored = false;
  for (const auto& c : d.scores) scored |= c.added && c.cv_gain_pct[1] > 50;
  EXPECT_TRUE(scored) << "the added delay pays on whole recordings left out";
  ASSERT_EQ(d.steps.back().model.sse_fold.size(), 2u);
  // Each recording left out is predicted by the fit on the other: the cross-validated SSE is the
  // sum of the two, and recomputed by hand from a fit on the other recording alone.
  const EmgTorqueModel& last = d.steps.back().model;
  EmgFitOptions one;
  one.train_fraction = 1.0;
  one.weight[0] = last.weight[0], one.weight[1] = last.weight[1];
  const EmgTorqueModel on_b = FitEmgModel(last.spec, {&b}, one);
  double sse = 0;
  for (int j = 0; j < 2; ++j) {
    const std::vector<double> p = PredictMoment(on_b, a, j);
    for (size_t i : WithinSpikeLimit(a.tau[j], 0, a.size())) sse += std::pow(last.weight[j] * (a.tau[j][i] - p[i]), 2);
  }
  EXPECT_NEAR(last.sse_fold[0][0] + last.sse_fold[0][1], sse, 1e-6 * sse);
}

TEST(EmgTorqueModel, ModelFileRoundTrips) {
  Truth tr;
  tr.delay = 0.05;
  tr.alpha_hip[0] = -20;  // RF against its action at the hip: held at zero by the signed fit
  const EmgRecording r = Synthetic(tr);
  EmgModelSpec s;
  s.signed_alphas = true;
  s.common_delay = 0.04;
  s.twitch = 0.03;
  s.delay_s[Muscle::kVM] = 0.05;
  s.delay_se[Muscle::kVM] = 0.002;
  s.passive[0] = true;
  s.moment_arm[1] = true;
  EmgTorqueModel m = FitEmgModel(s, {&r});
  m.papers_terms = FitEmgModel(EmgModelSpec{}, {&r}).terms;
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
  EXPECT_EQ(back.spec.Delay(Muscle::kRF), 0.04);
  EXPECT_EQ(back.spec.twitch, 0.03);
  ASSERT_EQ(back.range.channels, r.channels);
  EXPECT_TRUE(back.spec.bounded);
  for (int j = 0; j < 2; ++j) EXPECT_NEAR(back.range.q_lo[j], m.range.q_lo[j], 1e-5);
  EXPECT_TRUE(back.spec.passive[0]);
  EXPECT_TRUE(back.spec.moment_arm[1]);
  EXPECT_TRUE(back.spec.signed_alphas);
  EXPECT_TRUE(Term(m, 0, TermKind::kAlpha, "rect_fem_r").held);
  for (size_t k = 0; k < m.terms.size(); ++k) EXPECT_EQ(back.terms[k].held, m.terms[k].held) << m.terms[k].Name();
  ASSERT_EQ(back.papers_terms.size(), m.papers_terms.size());
  for (size_t k = 0; k < m.papers_terms.size(); ++k) {
    EXPECT_EQ(back.papers_terms[k].Name(), m.papers_terms[k].Name());
    EXPECT_NEAR(back.papers_terms[k].value, m.papers_terms[k].value, 1e-8 * (1 + std::abs(m.papers_terms[k].value)));
  }
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

// ---- Nonlinear terms outside the calibrated range, the twitch filter, the extrapolation report ----

namespace exotwin {
namespace {

TEST(EmgTorqueModel, ActivationShapeContinuesAlongItsTangent) {
  const double A = -2, h = 1e-6;
  auto slope = [&](double u) { return (ActivationShape(u + h, A) - ActivationShape(u - h, A)) / (2 * h); };
  // C1 at both ends of 0 <= u <= 1, linear outside (second difference zero).
  for (double u : {0.0, 1.0}) {
    EXPECT_NEAR(ActivationShape(u + 1e-9, A), ActivationShape(u - 1e-9, A), 1e-8);
    EXPECT_NEAR(slope(u + 1e-4), slope(u - 1e-4), 1e-3);
  }
  EXPECT_NEAR(ActivationShape(3.0, A), 1 + 2 * A * std::exp(A) / std::expm1(A), 1e-12);
  EXPECT_NEAR(ActivationShape(-0.5, A), -0.5 * A / std::expm1(A), 1e-12);
  EXPECT_NEAR(ActivationShape(2.0, A) - 2 * ActivationShape(1.5, A) + ActivationShape(1.0, A), 0.0, 1e-12);
}

TEST(EmgTorqueModel, TwitchFilterIsTheCriticallyDampedStepResponse) {
  // Step at t = 0 after rest: y = 1 - (1 + t / tau) e^{-t / tau}; unit gain; tau = 0: identity.
  const double tau = 0.05, dt = 0.0005;
  std::vector<double> t, u;
  for (int i = 0; i < 1000; ++i) t.push_back(dt * (i - 10)), u.push_back(i >= 10 ? 1.0 : 0.0);
  const std::vector<double> y = TwitchFilter(t, u, tau);
  for (size_t i = 10; i < t.size(); i += 37)
    EXPECT_NEAR(y[i], 1 - (1 + t[i] / tau) * std::exp(-t[i] / tau), 0.02) << t[i];
  const std::vector<double> flat(t.size(), 0.7), yf = TwitchFilter(t, flat, tau);
  for (double v : yf) EXPECT_NEAR(v, 0.7, 1e-12);  // unit gain, at rest from the start
  EXPECT_EQ(TwitchFilter(t, u, 0.0), u);
}

TEST(EmgTorqueModel, PassiveAndMomentArmTermsAreBoundedOutsideTheCalibratedAngles) {
  EmgRecording r;
  r.source = "angles";
  r.channels = {"vas_lat_r"};
  r.muscle = {Muscle::kVM};
  for (int i = 0; i < 400; ++i) {
    r.t.push_back(0.01 * i);
    r.e.resize(1);
    r.e[0].push_back(0.5);
    r.q[0].push_back(0.2);
    r.q[1].push_back(-0.2 - 0.005 * i);  // knee -0.2 .. -2.195 rad
    r.qd[0].push_back(0), r.qd[1].push_back(-0.5);
  }
  EmgModelSpec s;
  s.passive[1] = true;
  s.moment_arm[1] = true;
  EmgTerm passive, arm;
  passive.joint = 1, passive.kind = TermKind::kPassive;
  arm.joint = 1, arm.kind = TermKind::kAlphaQ, arm.channel = "vas_lat_r", arm.muscle = Muscle::kVM;
  const std::vector<double> free_p = TermColumn(passive, s, r);
  s.bounded = true;
  s.q_lo[0] = -1, s.q_hi[0] = 1, s.q_lo[1] = -1.2, s.q_hi[1] = -0.1;
  const std::vector<double> p = TermColumn(passive, s, r), a = TermColumn(arm, s, r);
  for (size_t i = 0; i < r.size(); ++i) {
    if (r.q[1][i] >= -1.2) EXPECT_DOUBLE_EQ(p[i], free_p[i]);                       // inside: as published
    else EXPECT_NEAR(a[i], 0.5 * -1.2, 1e-12);                                       // moment arm held
  }
  // Outside: continued along the tangent at -1.2 rad (second differences vanish), below the
  // unbounded exponential.
  const size_t k = 300;  // q = -1.7 rad
  EXPECT_NEAR(p[k + 20] - 2 * p[k + 10] + p[k], 0.0, 1e-9);
  EXPECT_LT(std::abs(p.back()), std::abs(free_p.back()));
}

TEST(EmgTorqueModel, ExtrapolationSharesCountTheSamplesOutside) {
  const EmgRecording r = Synthetic(Truth{});
  EmgCalibrationRange g = RangeOf({&r});
  EmgExtrapolation x = ExtrapolationOf(g, r);
  for (double v : x.envelope_share) EXPECT_EQ(v, 0.0);
  for (int j = 0; j < 2; ++j) {
    EXPECT_EQ(x.angle_share[j], 0.0);
    EXPECT_EQ(x.velocity_share[j], 0.0);
  }
  // Shrink the ranges: the shares are the counts beyond the new ends.
  g.e_hi[0] = 0.3, g.q_hi[0] = 0.3, g.qd_lo[1] = 0.0;
  x = ExtrapolationOf(g, r);
  auto count = [&](const std::vector<double>& v, auto pred) {
    return static_cast<double>(std::count_if(v.begin(), v.end(), pred)) / static_cast<double>(v.size());
  };
  EXPECT_DOUBLE_EQ(x.envelope_share[0], count(r.e[0], [](double v) { return v > 0.3; }));
  EXPECT_DOUBLE_EQ(x.angle_share[0], count(r.q[0], [](double v) { return v > 0.3; }));
  EXPECT_DOUBLE_EQ(x.velocity_share[1], count(r.qd[1], [](double v) { return v < 0.0; }));
  EXPECT_GT(x.velocity_share[1], 0.3);
}

// A joint's share of samples outside the calibration (JointOutsideShare) against a count written
// here: a sample is outside when either joint's angle or velocity, or the envelope of a channel whose
// muscle spans the joint, leaves its range. More than kOtherGaitShare outside: the papers' form
// predicts the joint, bit for bit; at or below it the calibrated form does.
TEST(EmgTorqueModel, AnotherGaitIsPredictedByThePapersForm) {
  Truth tr;
  tr.delay = 0.04;
  const EmgRecording r = Synthetic(tr);
  EmgModelSpec s;
  s.common_delay = 0.04;
  EmgTorqueModel m = FitEmgModel(s, {&r});
  m.papers_terms = FitEmgModel(EmgModelSpec{}, {&r}).terms;
  EmgTorqueModel papers;
  papers.terms = m.papers_terms;
  // The calibration's own recording: nothing outside; the calibrated form predicts.
  for (int j = 0; j < 2; ++j) {
    EXPECT_EQ(JointOutsideShare(m.range, r, j, false), 0.0);
    EXPECT_EQ(PredictMoment(m, r, j), PredictLinearMoment(m, r, j));
  }
  // A channel the calibration lacks is no input of its model: not counted.
  EmgRecording extra = r;
  extra.channels.push_back("glut_max1_r");
  extra.muscle.push_back(Muscle::kGMAX);
  extra.e.push_back(std::vector<double>(r.size(), 5.0));
  EXPECT_EQ(JointOutsideShare(m.range, extra, 0, false), 0.0);
  // The ranges shrunk: the med_gas_r envelope (spans the knee, not the hip) and the hip angle.
  EmgCalibrationRange g = m.range;
  g.e_hi[4] = 0.1, g.q_hi[0] = 0.25;
  for (int j = 0; j < 2; ++j) {
    double n = 0;
    for (size_t i = 0; i < r.size(); ++i) n += r.q[0][i] > 0.25 || (j == 1 && r.e[4][i] > 0.1);
    EXPECT_DOUBLE_EQ(JointOutsideShare(g, r, j, false), n / static_cast<double>(r.size())) << j;
  }
  EXPECT_GT(JointOutsideShare(g, r, 1, false), JointOutsideShare(g, r, 0, false));
  // Another gait: the angles widened by half about their means and every envelope doubled.
  EmgRecording other = r;
  for (int j = 0; j < 2; ++j) {
    double mean = 0;
    for (double q : r.q[j]) mean += q / static_cast<double>(r.size());
    for (size_t i = 0; i < r.size(); ++i)
      other.q[j][i] = mean + 1.5 * (r.q[j][i] - mean), other.qd[j][i] = 1.5 * r.qd[j][i];
  }
  for (auto& e : other.e)
    for (double& v : e) v *= 2;
  const EmgPrediction p = PredictMoments(m, other);
  for (int j = 0; j < 2; ++j) {
    EXPECT_GT(p.outside_share[j], kOtherGaitShare) << j;
    EXPECT_TRUE(p.papers[j]) << j;
    EXPECT_EQ(p.tau[j], PredictLinearMoment(papers, other, j)) << j;
    EXPECT_EQ(PredictMoment(m, other, j), p.tau[j]) << j;
    EXPECT_NE(p.tau[j], PredictLinearMoment(m, other, j)) << j;
  }
  // Without the papers' form (a file written before it): the calibrated form, whatever the share.
  EmgTorqueModel old = m;
  old.papers_terms.clear();
  const EmgPrediction q = PredictMoments(old, other);
  for (int j = 0; j < 2; ++j) {
    EXPECT_FALSE(q.papers[j]);
    EXPECT_EQ(q.tau[j], PredictLinearMoment(m, other, j));
  }
}

// ---- Collinear channels of one muscle ----

// Synthetic(Truth) plus a second vastus channel vas_med_r = vas_lat_r + independent noise of SD
// `sd`, and a knee law 100 vas_lat_r - 30 vas_med_r (the vastus' 70 split against its action).
EmgRecording TwoVasti(double sd) {
  EmgRecording r = Synthetic(Truth{});
  NormalRng<NormalPolar> rng(7);
  std::vector<double> med = r.e[0];
  for (double& v : med) v += sd * rng.Normal();
  r.channels.push_back("vas_med_r");
  r.muscle.push_back(Muscle::kVM);
  r.e.push_back(med);
  for (size_t i = 0; i < r.size(); ++i) r.tau[1][i] += 30 * (r.e[0][i] - med[i]);
  return r;
}

TEST(EmgTorqueModel, PooledChannelsAreOneAlphaOfTheirMeanEnvelope) {
  const EmgRecording r = TwoVasti(0.005);
  EmgModelSpec s;
  s.pooled = {Muscle::kVM};
  const std::vector<EmgTerm> terms = TermsOf(s, r);
  int vm = 0;
  for (const EmgTerm& t : terms)
    if (t.muscle == Muscle::kVM) {
      ++vm;
      EXPECT_EQ(t.channel, "vas_lat_r+vas_med_r");
      const std::vector<double> col = TermColumn(t, s, r);
      for (size_t i = 0; i < r.size(); i += 101) EXPECT_DOUBLE_EQ(col[i], 0.5 * (r.e[0][i] + r.e[5][i]));
    }
  EXPECT_EQ(vm, 1);  // the knee only
}

// The first note of `d` that contains `key` ("" if none).
std::string NoteWith(const EmgDiagnosis& d, const std::string& key) {
  for (const std::string& n : d.notes)
    if (n.find(key) != std::string::npos) return n;
  return std::string();
}

// The loop's options for the linear form alone (signs, pooling and their gates only).
EmgDiagnoseOptions LinearOnly() {
  EmgDiagnoseOptions o;
  o.max_steps = 0, o.robust_candidate = false;
  return o;
}

TEST(EmgTorqueModel, CollinearChannelsArePooledOrReportedNotSeparable) {
  const EmgDiagnoseOptions lin = LinearOnly();
  auto note_of = [](const EmgDiagnosis& d) { return NoteWith(d, "VM's channels"); };
  {  // nearly identical channels: pooling costs < 5 % of the cross-validated error, alpha ~ 70
    const EmgRecording r = TwoVasti(0.005);
    const EmgDiagnosis d = DiagnoseEmg({&r}, lin);
    ASSERT_EQ(d.calibration.spec.pooled, std::vector<Muscle>{Muscle::kVM}) << note_of(d);
    EXPECT_NE(note_of(d).find("pooled"), std::string::npos);
    EXPECT_NEAR(Term(d.calibration, 1, TermKind::kAlpha, "vas_lat_r+vas_med_r").value, 70, 3.5);
  }
  {  // channels that differ: pooling would cost more: kept apart, reported not separable
    const EmgRecording r = TwoVasti(0.03);
    const EmgDiagnosis d = DiagnoseEmg({&r}, lin);
    EXPECT_TRUE(d.calibration.spec.pooled.empty());
    EXPECT_NE(note_of(d).find("not separable"), std::string::npos) << note_of(d);
    EXPECT_NEAR(Term(d.calibration, 1, TermKind::kAlpha, "vas_med_r").value, -30, 3);
  }
}

// A channel against its muscle's action: held at zero by the signed fit and reported, unless
// freeing its sign pays on the data left out (the loop's gates), as a strong one does.
TEST(EmgTorqueModel, AlphaAgainstItsMuscleIsHeldAtZeroUnlessItsSignPays) {
  const EmgDiagnoseOptions lin = LinearOnly();
  auto note_of = [](const EmgDiagnosis& d) { return NoteWith(d, "alpha[rect_fem_r] at the hip"); };
  auto diagnose = [&](double alpha_rf_hip) {
    Truth tr;
    tr.alpha_hip[0] = alpha_rf_hip;
    const EmgRecording r = Synthetic(tr);
    return DiagnoseEmg({&r}, lin);
  };
  const EmgDiagnosis weak = diagnose(-1);  // -1 N m at full activation (envelope <= 0.52): below the noise
  ASSERT_EQ(weak.steps.size(), 2u);
  EXPECT_EQ(weak.steps[1].added, "alphas signed (muscles pull)");
  EXPECT_TRUE(weak.calibration.spec.signed_alphas);
  const EmgTerm& held = Term(weak.calibration, 0, TermKind::kAlpha, "rect_fem_r");
  EXPECT_TRUE(held.held);
  EXPECT_EQ(held.value, 0.0);
  EXPECT_NE(note_of(weak).find("held at zero"), std::string::npos) << note_of(weak);
  EXPECT_NE(note_of(weak).find("not separable"), std::string::npos) << note_of(weak);
  // Every other alpha fitted with its sign, near the truth.
  EXPECT_NEAR(Term(weak.calibration, 0, TermKind::kAlpha, "semimem_r").value, -40, 2);
  EXPECT_NEAR(Term(weak.calibration, 1, TermKind::kAlpha, "vas_lat_r").value, 70, 3.5);
  // -30 N m: freeing the signs pays cross-validated; the alpha is fitted and reported against RF's action.
  const EmgDiagnosis strong = diagnose(-30);
  ASSERT_EQ(strong.steps.size(), 3u);
  EXPECT_EQ(strong.steps[2].added, "alphas_free_of_sign");
  EXPECT_FALSE(strong.calibration.spec.signed_alphas);
  const EmgTerm& freed = Term(strong.calibration, 0, TermKind::kAlpha, "rect_fem_r");
  EXPECT_FALSE(freed.held);
  EXPECT_NEAR(freed.value, -30, 1.5);
  EXPECT_NE(note_of(strong).find("against the RF's action"), std::string::npos) << note_of(strong);
}

// ---- A synthetic law with trial-to-trial variation ----
//
// Gait-like trials drawn from one law: the linear form (HJ15 eq. 26) with one electromechanical
// delay common to every channel. Each trial has its own cadence, burst amplitudes and burst timing
// per channel, and every stride varies around them (amplitude, timing), as real trials differ; the
// envelopes and angles are phase-locked to the stride, as in gait.
struct Law {
  double delay = 0.04;  // s
  double noise = 1.0;   // N m
};

EmgRecording GaitTrial(const Law& law, uint64_t seed) {
  NormalRng<NormalPolar> rng(seed);
  EmgRecording r = GaitEnvelopesAndAngles(rng, "gait trial " + std::to_string(seed));
  const size_t n = r.size();
  // The law: Truth's alphas, beta, gamma, offset on the envelopes delayed by law.delay.
  const Truth tr;
  std::vector<std::vector<double>> a(5);
  std::vector<double> tq(n);
  for (size_t i = 0; i < n; ++i) tq[i] = r.t[i] - law.delay;
  for (int c = 0; c < 5; ++c) a[c] = law.delay > 0 ? Interpolate(r.t, r.e[c], tq) : r.e[c];
  LinearLawMoments(tr, a, law.noise, rng, &r);
  return r;
}

// Names of the causes the loop added (steps after the linear form).
std::string Added(const EmgDiagnosis& d) {
  std::string o;
  for (size_t i = 1; i < d.steps.size(); ++i) o += d.steps[i].added + "; ";
  return o;
}

TEST(EmgSyntheticLaw, CommonDelayIsNamedAloneAndCarriesToAnotherTrial) {
  const Law law;
  const EmgRecording a = GaitTrial(law, 11), b = GaitTrial(law, 12);
  const EmgDiagnosis d = DiagnoseEmg({&a});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  const EmgModelSpec& s = d.calibration.spec;
  EXPECT_NEAR(s.common_delay, law.delay, 0.010);
  EXPECT_TRUE(s.delay_s.empty());
  EXPECT_EQ(s.twitch, 0.0);
  EXPECT_EQ(s.a_shape, 0.0);
  EXPECT_FALSE(s.moment_arm[0] || s.moment_arm[1] || s.passive[0] || s.passive[1] || s.gmax_proxy || s.robust);
  ASSERT_EQ(d.steps.size(), 2u) << Added(d);
  // Another trial of the same law: predicted, never fitted.
  for (int j = 0; j < 2; ++j) {
    const double r2 = R2(b.tau[j], PredictMoment(d.calibration, b, j));
    std::printf("  %s predicted, %s: R^2 %.4f (cross-validated on %s: %.4f)\n", b.source.c_str(), j ? "knee" : "hip", r2,
                a.source.c_str(), d.steps.back().model.figures[j].r2_cv);
    EXPECT_GE(r2, 0.97);
  }
}

TEST(EmgSyntheticLaw, NoDelayInTheLawNoDelayNamed) {
  Law law;
  law.delay = 0;
  const EmgRecording a = GaitTrial(law, 21), b = GaitTrial(law, 22);
  const EmgDiagnosis d = DiagnoseEmg({&a});
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  EXPECT_EQ(d.calibration.spec.common_delay, 0.0);
  EXPECT_TRUE(d.calibration.spec.delay_s.empty());
  EXPECT_EQ(d.calibration.spec.twitch, 0.0);
  EXPECT_EQ(d.steps.size(), 1u) << Added(d);
  for (int j = 0; j < 2; ++j) EXPECT_GE(R2(b.tau[j], PredictMoment(d.calibration, b, j)), 0.97);
}

// The band ceiling (emg_diagnose.h BandCeiling) against the closed form of white noise: the law's
// own moment lies below the estimate's band, white noise of variance s^2 spreads evenly up to fs/2,
// so the measured share above band_hz is s^2 (1 - band_hz / (fs/2)) / var(tau) (the law's residue
// above the band, at most kBandResidue of its variance, within the tolerance). The estimate's own
// R^2 does not pass the ceiling; without noise the ceiling is 1 to within the residue.
TEST(EmgSyntheticLaw, BandCeilingIsTheWhiteNoiseAboveTheEstimatesBand) {
  for (double noise : {0.01, 4.0}) {
    Law law;
    law.noise = noise;
    const EmgRecording a = GaitTrial(law, 31);
    EmgModelSpec spec;
    spec.common_delay = law.delay;
    const EmgTorqueModel m = FitEmgModel(spec, {&a}, EmgFitOptions{1.0});
    for (int j = 0; j < 2; ++j) {
      const EmgBandCeiling c = BandCeiling(m, {&a}, j);
      double mean = 0, var = 0;
      for (double v : a.tau[j]) mean += v / static_cast<double>(a.size());
      for (double v : a.tau[j]) var += (v - mean) * (v - mean) / static_cast<double>(a.size());
      const double expected = noise * noise * (1 - c.band_hz / 50.0) / var;
      const double r2 = R2(a.tau[j], PredictMoment(m, a, j));
      std::printf("  noise %g N m, %s: band %.1f Hz, share above %.4f (white noise: %.4f), ceiling %.4f, R^2 %.4f\n",
                  noise, j ? "knee" : "hip", c.band_hz, c.share_above, expected, c.r2, r2);
      EXPECT_GT(c.band_hz, 0.5);
      EXPECT_LT(c.band_hz, 10.0);
      EXPECT_NEAR(c.share_above, expected, 0.002 + 0.1 * expected);
      EXPECT_LE(c.estimate_share, 1.2 * kBandResidue);
      EXPECT_LE(r2, c.r2 + 1e-9);
      if (noise < 0.1) {
        EXPECT_GT(c.r2, 1 - kBandResidue);
      }
    }
  }
}

}  // namespace
}  // namespace exotwin
