// The black box (diagnosis/black_box.h) against known ground truth: on a smooth function of six
// inputs plus noise it recovers >= 90 % of the explainable variance on unseen rows; on pure noise it
// explains ~0 % (within the sampling noise, not negative beyond it); the same seed gives the same
// bits.
#include "diagnosis/black_box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/rng.h"

namespace exotwin {
namespace {

using Normal = NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>>;

// Rows of six inputs (a constant one among them, dropped by the standardization) and the function
// f = sin(x0) + 0.5 x1 x2 + 0.3 cos(2 x3) + 0.2 x4 (the inputs N(0, 1), x5 = 3).
Eigen::MatrixXd Inputs(Normal& rng, int n) {
  Eigen::MatrixXd X(n, 6);
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 5; ++c) X(i, c) = rng.Normal();
    X(i, 5) = 3;
  }
  return X;
}
double F(const Eigen::MatrixXd& X, int i) {
  return std::sin(X(i, 0)) + 0.5 * X(i, 1) * X(i, 2) + 0.3 * std::cos(2 * X(i, 3)) + 0.2 * X(i, 4);
}

std::vector<bool> LastQuarter(int n) {
  std::vector<bool> v(static_cast<size_t>(n), false);
  for (int i = 3 * n / 4; i < n; ++i) v[static_cast<size_t>(i)] = true;
  return v;
}

TEST(BlackBox, RecoversASmoothFunctionOfTheInputs) {
  Normal rng(5);
  const int n = 6000, m = 3000;
  const Eigen::MatrixXd X = Inputs(rng, n), Xt = Inputs(rng, m);
  Eigen::MatrixXd Y(n, 1);
  for (int i = 0; i < n; ++i) Y(i, 0) = F(X, i) + 0.1 * rng.Normal();
  const BlackBox bb = BlackBox::Fit(X, Y, LastQuarter(n));
  const Eigen::MatrixXd P = bb.Predict(Xt);
  double err = 0, var = 0, mean = 0;
  for (int i = 0; i < m; ++i) mean += F(Xt, i) / m;
  for (int i = 0; i < m; ++i) err += std::pow(F(Xt, i) - P(i, 0), 2), var += std::pow(F(Xt, i) - mean, 2);
  const double recovered = 1 - err / var;
  std::printf("explainable variance recovered: %.1f %% (length %.2f sqrt(d), ridge %.0e)\n", 100 * recovered,
              bb.bandwidth(0), bb.ridge(0));
  EXPECT_GE(recovered, 0.90);
}

// Pure noise: the held-out share explained, 1 - SSE(y - prediction) / SSE(y - train mean), is within
// +-2 % (the sampling noise of a few hundred parameters against 4000 rows: about p / n = 7 %, shrunk
// by the ridge the validation rows choose).
TEST(BlackBox, ExplainsNothingOfPureNoise) {
  Normal rng(9);
  const int n = 4000, m = 4000;
  const Eigen::MatrixXd X = Inputs(rng, n), Xt = Inputs(rng, m);
  Eigen::MatrixXd Y(n, 2), Yt(m, 2);
  for (int i = 0; i < n; ++i) Y(i, 0) = rng.Normal(), Y(i, 1) = 5 + 0.01 * rng.Normal();
  for (int i = 0; i < m; ++i) Yt(i, 0) = rng.Normal(), Yt(i, 1) = 5 + 0.01 * rng.Normal();
  const BlackBox bb = BlackBox::Fit(X, Y, LastQuarter(n));
  const Eigen::MatrixXd P = bb.Predict(Xt);
  for (int k = 0; k < 2; ++k) {
    const double mean = Y.col(k).mean();
    const double before = (Yt.col(k).array() - mean).square().sum(), after = (Yt.col(k) - P.col(k)).squaredNorm();
    const double share = 1 - after / before;
    std::printf("noise column %d: %.2f %% explained\n", k, 100 * share);
    EXPECT_NEAR(share, 0.0, 0.02) << k;
  }
}

TEST(BlackBox, SameSeedSameBits) {
  Normal rng(2);
  const int n = 1200;
  const Eigen::MatrixXd X = Inputs(rng, n);
  Eigen::MatrixXd Y(n, 1);
  for (int i = 0; i < n; ++i) Y(i, 0) = F(X, i) + 0.1 * rng.Normal();
  BlackBoxOptions o;
  o.seed = 17;
  const Eigen::MatrixXd a = BlackBox::Fit(X, Y, LastQuarter(n), o).Predict(X);
  const Eigen::MatrixXd b = BlackBox::Fit(X, Y, LastQuarter(n), o).Predict(X);
  EXPECT_TRUE((a.array() == b.array()).all());
  o.seed = 18;
  const Eigen::MatrixXd c = BlackBox::Fit(X, Y, LastQuarter(n), o).Predict(X);
  EXPECT_FALSE((a.array() == c.array()).all());
  // Bad sizes.
  EXPECT_THROW(BlackBox::Fit(X, Y.topRows(10), LastQuarter(n)), std::invalid_argument);
  EXPECT_THROW(BlackBox::Fit(X, Y, std::vector<bool>(static_cast<size_t>(n), false)), std::invalid_argument);
}

// Several targets on the same rows (AssessModel's ceilings of two models: one fit) are independent
// fits: each column as fitted alone, to round-off; the length scales on two threads give the same
// bits as on one.
TEST(BlackBox, ColumnsAreIndependentFitsAndThreadsChangeNoBit) {
  Normal rng(4);
  const int n = 2000, m = 1000;
  const Eigen::MatrixXd X = Inputs(rng, n), Xt = Inputs(rng, m);
  Eigen::MatrixXd Y(n, 3);
  for (int i = 0; i < n; ++i) Y(i, 0) = F(X, i) + 0.1 * rng.Normal(), Y(i, 1) = rng.Normal(), Y(i, 2) = 0.3 * X(i, 0) * X(i, 0);
  BlackBoxOptions one, two;
  two.threads = 2;
  const BlackBox all = BlackBox::Fit(X, Y, LastQuarter(n), one);
  const Eigen::MatrixXd P = all.Predict(Xt);
  for (int k = 0; k < 3; ++k) {
    const BlackBox alone = BlackBox::Fit(X, Y.col(k), LastQuarter(n), one);
    EXPECT_EQ(alone.bandwidth(0), all.bandwidth(k)) << k;
    EXPECT_EQ(alone.ridge(0), all.ridge(k)) << k;
    const Eigen::MatrixXd Pk = alone.Predict(Xt);
    EXPECT_LE((Pk.col(0) - P.col(k)).cwiseAbs().maxCoeff(), 1e-9 * (1 + P.col(k).cwiseAbs().maxCoeff())) << k;
  }
  const Eigen::MatrixXd P2 = BlackBox::Fit(X, Y, LastQuarter(n), two).Predict(Xt);
  EXPECT_TRUE((P.array() == P2.array()).all());
}

}  // namespace
}  // namespace exotwin
