// Step 7's resamples (diagnosis/motion_spread.cc Resample) against closed forms: on a straight line
// y = a x + white noise, the block bootstrap's standard deviation of the fitted slope is the least
// squares' standard error sigma / sqrt(sum x^2), and each fifth left out moves the slope by exactly
// the closed-form least squares of the other four fifths.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "diagnosis/motion_fit_internal.h"

namespace exotwin {
namespace motion {
namespace {

TEST(MotionSpread, BootstrapOfALineIsItsStandardErrorAndTheFifthsAreTheirOwnFits) {
  const size_t n = 8000, blocks = 400;  // 20 rows a block, the noise white: blocks independent
  const double a = 0.7, sigma = 0.3;
  NormalRng<NormalPolar> rng(11);
  BlockGrams G(blocks, 1);
  std::vector<double> x(n), y(n);
  double sxx = 0, sfx[5] = {0, 0, 0, 0, 0}, sfy[5] = {0, 0, 0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    x[i] = 1 + 0.3 * std::sin(0.01 * static_cast<double>(i));
    y[i] = a * x[i] + sigma * rng.Normal();
    const size_t f = 5 * i / n;
    G.Add(Eigen::VectorXd::Constant(1, x[i]), y[i], i / (n / blocks), f);
    sxx += x[i] * x[i], sfx[f] += x[i] * x[i], sfy[f] += x[i] * y[i];
  }
  std::vector<double> sd, lo, hi;
  Resample(G, 1, [](const Eigen::VectorXd& s, std::vector<double>* v) { return *v = {s[0]}, true; }, &sd, &lo, &hi);
  const double se = sigma / std::sqrt(sxx);
  std::printf("bootstrap sd %.5g, standard error %.5g\n", sd[0], se);
  // The sd's own relative error: ~5 % from 200 draws, ~4 % from 400 blocks' residuals (seeds 11-15: 0.90-1.11).
  EXPECT_NEAR(sd[0], se, 0.15 * se);
  double flo = INFINITY, fhi = -INFINITY, tx = 0, ty = 0;
  for (int f = 0; f < 5; ++f) tx += sfx[f], ty += sfy[f];
  for (int f = 0; f < 5; ++f) {
    const double slope = (ty - sfy[f]) / (tx - sfx[f]);
    flo = std::fmin(flo, slope), fhi = std::fmax(fhi, slope);
  }
  EXPECT_NEAR(lo[0], flo, 1e-12);
  EXPECT_NEAR(hi[0], fhi, 1e-12);
  // A value not defined on any resample: NaN.
  Resample(G, 1, [](const Eigen::VectorXd&, std::vector<double>*) { return false; }, &sd, &lo, &hi);
  EXPECT_TRUE(std::isnan(sd[0]) && std::isnan(lo[0]) && std::isnan(hi[0]));
}

}  // namespace
}  // namespace motion
}  // namespace exotwin
