// Pearson correlation against closed forms: exact lines give +-1 whatever their offset and scale,
// a constant gives 0, orthogonal centred signals give 0, and the sample range is honoured.
#include "dsp/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"

namespace exotwin {
namespace {

// AR(1) x_k = phi x_(k-1) + white noise: rho(k) = phi^k, so 1 + 2 sum phi^k = (1 + phi) / (1 - phi)
// (truncated where phi^k < 0.05: within 2 * 0.05 / (1 - phi) of it, plus the sampling error).
TEST(Statistics, AutocorrelationLengthOfAnAr1ProcessIsItsClosedForm) {
  for (double phi : {0.0, 0.5, 0.8}) {
    NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> rng(3);
    std::vector<double> x(200000);
    double v = 0;
    for (double& s : x) s = v = phi * v + rng.Normal();
    const double exact = (1 + phi) / (1 - phi);
    const double truncation = 2 * 0.05 / (1 - phi);
    EXPECT_NEAR(AutocorrelationLength(x.data(), x.size()), exact, truncation + 0.05 * exact) << phi;
  }
  const std::vector<double> constant(100, 2.0);
  EXPECT_EQ(AutocorrelationLength(constant.data(), constant.size()), 1.0);
}

TEST(Statistics, PearsonAgainstClosedForms) {
  std::vector<double> x, up, down, flat, s, c;
  for (int i = 0; i < 400; ++i) {
    const double t = 2 * M_PI * i / 400.0;
    x.push_back(i);
    up.push_back(3.0 * i - 7.0);       // exact line, offset: +1
    down.push_back(100.0 - 0.5 * i);   // exact line, falling: -1
    flat.push_back(4.2);
    s.push_back(5.0 + std::sin(t));    // sin and cos over whole periods: 0, offsets removed
    c.push_back(-3.0 + std::cos(t));
  }
  EXPECT_NEAR(Pearson(x, up), 1.0, 1e-12);
  EXPECT_NEAR(Pearson(x, down), -1.0, 1e-12);
  EXPECT_EQ(Pearson(x, flat), 0.0);
  EXPECT_NEAR(Pearson(s, c), 0.0, 1e-12);
  // Over the first quarter period sin rises while cos falls: strongly negative, and equal to the
  // definition evaluated on that range alone.
  const size_t q = 100;
  double ms = 0, mc = 0;
  for (size_t i = 0; i < q; ++i) ms += s[i], mc += c[i];
  ms /= q, mc /= q;
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < q; ++i) sxy += (s[i] - ms) * (c[i] - mc), sxx += std::pow(s[i] - ms, 2), syy += std::pow(c[i] - mc, 2);
  EXPECT_NEAR(Pearson(s, c, 0, q), sxy / std::sqrt(sxx * syy), 1e-12);
  EXPECT_LT(Pearson(s, c, 0, q), -0.9);
  EXPECT_EQ(Pearson(x, up, 5, 5), 0.0);  // empty range
}

// PercentileInPlace (selection) gives Percentile of the sorted values, the same number, at ranks on and
// between the values, with ties and with one value.
TEST(Statistics, PercentileBySelectionIsThePercentileOfTheSortedValues) {
  Rng rng(11);
  for (size_t n : {1, 2, 7, 1000}) {
    std::vector<double> v(n);
    for (double& x : v) x = std::floor(rng.Uniform(0, 50));  // ties
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (double p : {0.0, 0.1, 0.25, 0.5, 0.9, 0.999, 1.0}) {
      std::vector<double> w = v;
      EXPECT_EQ(PercentileInPlace(w, p), Percentile(sorted, p)) << "n " << n << " p " << p;
    }
  }
  std::vector<double> empty;
  EXPECT_TRUE(std::isnan(PercentileInPlace(empty, 0.5)));
}

// The normal quantile against tabulated values (Abramowitz & Stegun 26.2) and as Phi's inverse.
TEST(Statistics, NormalQuantileAgainstTables) {
  EXPECT_NEAR(NormalQuantile(0.975), 1.959963985, 1e-9);
  EXPECT_NEAR(NormalQuantile(0.995), 2.575829304, 1e-9);
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(NormalQuantile(1 - 1e-6), 4.753424309, 1e-8);
  EXPECT_NEAR(NormalQuantile(0.01), -2.326347874, 1e-9);
  for (double z : {-6.0, -2.5, -0.3, 0.7, 3.1, 7.5})
    EXPECT_NEAR(NormalSurvival(NormalQuantile(NormalSurvival(-z))), NormalSurvival(z), 1e-12 + 1e-9 * NormalSurvival(z)) << z;
  EXPECT_NEAR(NormalSurvival(1.959963985), 0.025, 1e-10);
}

// The chi-square tail against its closed forms (2 dof: exp(-x/2); 1 dof: erfc(sqrt(x/2)); 4 dof:
// (1 + x/2) exp(-x/2)) and tabulated upper quantiles (NIST/SEMATECH e-Handbook 1.3.6.7.4).
TEST(Statistics, ChiSquareAgainstClosedFormsAndTables) {
  for (double x : {0.01, 0.5, 1.0, 3.0, 10.0, 40.0}) {
    EXPECT_NEAR(ChiSquareSurvival(x, 2), std::exp(-x / 2), 1e-14) << x;
    EXPECT_NEAR(ChiSquareSurvival(x, 1), std::erfc(std::sqrt(x / 2)), 1e-13) << x;
    EXPECT_NEAR(ChiSquareSurvival(x, 4), (1 + x / 2) * std::exp(-x / 2), 1e-13) << x;
  }
  EXPECT_EQ(ChiSquareSurvival(0, 3), 1.0);
  EXPECT_NEAR(ChiSquareUpperQuantile(0.05, 1), 3.841, 1e-3);
  EXPECT_NEAR(ChiSquareUpperQuantile(0.01, 10), 23.209, 1e-3);
  EXPECT_NEAR(ChiSquareUpperQuantile(0.01, 20), 37.566, 1e-3);
  EXPECT_NEAR(ChiSquareUpperQuantile(0.001, 50), 86.661, 1e-3);
  EXPECT_NEAR(ChiSquareUpperQuantile(0.05, 100), 124.342, 1e-3);
}

// Ljung-Box Q of seeded white Gaussian noise follows chi2(m): over 2000 series its mean is m (sd of
// the mean sqrt(2 m / 2000)) and it exceeds the 5 % quantile in 5 % of them (binomial sd 0.5 %);
// an AR(1) series with phi = 0.3 is rejected.
TEST(Statistics, LjungBoxOfWhiteNoiseIsChiSquare) {
  const size_t n = 400, m = 10;
  NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> rng(11);
  const double q95 = ChiSquareUpperQuantile(0.05, m);
  double sum = 0;
  int over = 0;
  const int S = 2000;
  std::vector<double> x(n);
  for (int s = 0; s < S; ++s) {
    for (double& v : x) v = rng.Normal();
    const double q = LjungBoxQ(x.data(), n, m);
    sum += q;
    over += q > q95;
  }
  EXPECT_NEAR(sum / S, static_cast<double>(m), 4 * std::sqrt(2.0 * m / S) + 0.2);
  EXPECT_NEAR(over / static_cast<double>(S), 0.05, 0.015);
  double v = 0;
  for (double& s : x) s = v = 0.3 * v + rng.Normal();
  EXPECT_GT(LjungBoxQ(x.data(), n, m), ChiSquareUpperQuantile(1e-6, m));
  // The sample autocorrelation of a line of period 4 (1, 0, -1, 0, ...): r(2) near -1.
  std::vector<double> p;
  for (int i = 0; i < 400; ++i) p.push_back(std::cos(M_PI * i / 2));
  EXPECT_NEAR(SampleAutocorrelation(p.data(), p.size(), 2)[1], -1.0, 0.01);
}

}  // namespace
}  // namespace exotwin
