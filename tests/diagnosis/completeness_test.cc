// The residual tests (diagnosis/completeness.h) against known distributions: white noise passes at
// the family-wise level (a Bonferroni verdict at 1 % rejects at most 1 % of seeds), an AR(1) series
// passes once decimated at the step its known autocorrelation gives and fails undecimated, filtered
// white noise passes at CompletenessStep; a left-over structure of the motion fails the test that
// names it.
#include "diagnosis/completeness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "dsp/butterworth.h"

namespace exotwin {
namespace {

using Normal = NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>>;

// A segment of n rows: a motion of two harmonics per joint (rows 0.005 s apart), residual zeros.
ResidualSegment Motion(size_t n, double phase) {
  ResidualSegment s;
  for (size_t i = 0; i < n; ++i) {
    const double t = 0.005 * static_cast<double>(i);
    const double w1 = 2 * M_PI * 0.7, w2 = 2 * M_PI * 1.3;
    s.t.push_back(t);
    s.q.push_back(0.4 * std::sin(w1 * t + phase) + 0.1 * std::sin(w2 * t));
    s.qd.push_back(0.4 * w1 * std::cos(w1 * t + phase) + 0.1 * w2 * std::cos(w2 * t));
    s.qdd.push_back(-0.4 * w1 * w1 * std::sin(w1 * t + phase) - 0.1 * w2 * w2 * std::sin(w2 * t));
    s.tau_R.push_back(5 * std::sin(s.q.back()) + 0.3 * s.qdd.back() + 2);
    s.q_other.push_back(0.3 * std::cos(0.9 * t));
    s.qd_other.push_back(-0.27 * std::sin(0.9 * t));
    s.e.push_back(0);
  }
  return s;
}

const CompletenessTest* Find(const JointCompleteness& c, const std::string& name) {
  for (const auto& t : c.tests)
    if (t.name == name) return &t;
  return nullptr;
}

// White Gaussian noise on two segments: complete on at least 97 of 100 seeds (expected >= 99), every
// test present (1 whiteness + 9 linear + 1 + 12 + 3 nonlinear), each statistic's threshold the
// closed-form quantile at alpha / 26.
TEST(Completeness, WhiteNoiseIsCompleteAtTheFamilyWiseLevel) {
  int complete = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    Normal rng(seed);
    std::vector<ResidualSegment> segs = {Motion(600, 0.0), Motion(400, 1.0)};
    for (auto& s : segs)
      for (double& e : s.e) e = 0.03 * rng.Normal();
    const JointCompleteness c = AssessCompleteness(segs, 7, 0.0);
    ASSERT_TRUE(c.assessed);
    ASSERT_EQ(c.tests.size(), 26u);
    EXPECT_EQ(c.rows, 1000u);
    EXPECT_EQ(c.step, 7u);
    complete += c.complete;
    if (seed == 1) {
      const CompletenessTest* w = Find(c, "whiteness");
      ASSERT_NE(w, nullptr);
      // chi2 with 20 dof at 0.01 / 26: between the tabulated 0.001 (45.315) and 0.0001 (52.39) points.
      EXPECT_GT(w->threshold, 45.315);
      EXPECT_LT(w->threshold, 52.39);
      const CompletenessTest* x = Find(c, "xcorr_qd");
      ASSERT_NE(x, nullptr);
      // 11 lags, two-sided: z at 1 - 0.01 / (26 * 22).
      EXPECT_NEAR(x->threshold, 4.1374, 2e-3);
    }
  }
  EXPECT_GE(complete, 97);
}

// AR(1) x_k = 0.9 x_(k-1) + w_k: rho(k) = 0.9^k, below 0.05 from k = 29. Decimated at that step the
// series passes (on at least 19 of 20 seeds); undecimated it fails whiteness on every seed.
TEST(Completeness, Ar1PassesDecimatedAtItsAutocorrelationStep) {
  std::vector<double> acf;
  for (int k = 0; k < 200; ++k) acf.push_back(std::pow(0.9, k));
  const size_t step = DecimationStep(acf, 0.05);
  EXPECT_EQ(step, 29u);  // 0.9^28 = 0.0523, 0.9^29 = 0.0471
  int pass = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    Normal rng(100 + seed);
    const size_t n = 29 * 500;
    std::vector<double> x(n);
    double v = 0;
    for (double& s : x) s = v = 0.9 * v + rng.Normal();
    ResidualSegment full = Motion(n, 0.0), dec = Motion(500, 0.3);
    full.e = x;
    for (size_t i = 0; i < 500; ++i) dec.e[i] = x[i * step];
    pass += AssessCompleteness({dec}, step, 0.0).complete;
    const JointCompleteness f = AssessCompleteness({full}, 1, 0.0);
    EXPECT_FALSE(f.complete);
    EXPECT_FALSE(Find(f, "whiteness")->pass);
  }
  EXPECT_GE(pass, 19);
}

// White noise through the zero-phase Butterworth at 10 Hz, sampled at 1 kHz: CompletenessStep reads
// the filter's autocorrelation (of lag 1/(2 fc) = 50 rows of an ideal low-pass, longer for the
// Butterworth's tail); decimated there it passes on at least 19 of 20 seeds.
TEST(Completeness, FilteredNoisePassesAtTheFiltersStep) {
  const size_t step = CompletenessStep(1000, 10);
  EXPECT_GE(step, 50u);
  EXPECT_LE(step, 200u);
  EXPECT_EQ(CompletenessStep(1000, 0), 1u);
  const auto sos = dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1000, 10);
  int pass = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    Normal rng(300 + seed);
    std::vector<double> w(60000);
    for (double& s : w) s = rng.Normal();
    const std::vector<double> y = dsp::FiltFilt(sos, w);
    const size_t m = y.size() / step;
    ResidualSegment s = Motion(m, 0.2);
    for (size_t i = 0; i < m; ++i) s.e[i] = y[i * step];
    pass += AssessCompleteness({s}, step, 0.0).complete;
  }
  EXPECT_GE(pass, 19);
}

// Structure left over: a Coulomb-like (0.02 sgn(qd)) term in noise of 0.03 is caught by its
// cross-correlation with sgn(qd), and passes where the material floor is above its size; an even
// function of qd (0.03 (qd^2 - mean)) by u2_e_qd; noise whose size follows |qd| (heteroscedastic,
// zero mean) by u2_e2_qd.
TEST(Completeness, StructureFailsTheTestThatNamesIt) {
  Normal rng(7);
  std::vector<ResidualSegment> sgn = {Motion(2000, 0.0)}, even = sgn, hetero = sgn;
  double mean_qd2 = 0;
  for (double v : sgn[0].qd) mean_qd2 += v * v / 2000;
  for (size_t i = 0; i < 2000; ++i) {
    const double qd = sgn[0].qd[i];
    sgn[0].e[i] = 0.03 * rng.Normal() + 0.02 * (qd > 0 ? 1 : -1);
    even[0].e[i] = 0.03 * rng.Normal() + 0.03 * (qd * qd - mean_qd2);
    hetero[0].e[i] = 0.03 * rng.Normal() * (0.2 + std::abs(qd));
  }
  const JointCompleteness a = AssessCompleteness(sgn, 1, 0.0), b = AssessCompleteness(even, 1, 0.0), c = AssessCompleteness(hetero, 1, 0.0);
  EXPECT_FALSE(a.complete);
  EXPECT_FALSE(Find(a, "xcorr_sgn_qd")->pass);
  EXPECT_FALSE(b.complete);
  EXPECT_FALSE(Find(b, "u2_e_qd")->pass);
  EXPECT_FALSE(c.complete);
  EXPECT_FALSE(Find(c, "u2_e2_qd")->pass);
  // The size of the left-over Coulomb: |r| RMS(e) = 0.02 (its own RMS) to within the noise's share.
  EXPECT_NEAR(Find(a, "xcorr_sgn_qd")->size, 0.02, 0.002);
  // Below a material floor of 0.05 it passes; above one of 0.01 it fails.
  EXPECT_TRUE(AssessCompleteness(sgn, 1, 0.05).complete);
  EXPECT_FALSE(AssessCompleteness(sgn, 1, 0.01).complete);
}

// A segment shorter than kMinSegmentRows is left out; with none the joint is not assessed. A signal
// constant on a segment (a held joint) drops its tests.
TEST(Completeness, ShortSegmentsAndConstantSignals) {
  ResidualSegment s = Motion(10, 0);
  EXPECT_FALSE(AssessCompleteness({s}, 1, 0.0).assessed);
  EXPECT_TRUE(AssessCompleteness({s}, 1, 0.0).complete);
  ResidualSegment held = Motion(500, 0);
  Normal rng(3);
  for (double& e : held.e) e = rng.Normal();
  held.q_other.assign(500, 0.0), held.qd_other.assign(500, 0.0);
  const JointCompleteness c = AssessCompleteness({held}, 1, 0.0);
  EXPECT_EQ(Find(c, "xcorr_q_other"), nullptr);
  EXPECT_EQ(Find(c, "u2_e2_qd_other"), nullptr);
  EXPECT_EQ(c.tests.size(), 26u - 6u);
  EXPECT_THROW(AssessCompleteness({held}, 1, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(AssessCompleteness({held}, 1, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin
