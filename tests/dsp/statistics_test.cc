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

}  // namespace
}  // namespace exotwin
