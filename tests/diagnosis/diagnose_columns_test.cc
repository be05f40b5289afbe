// SignConstrainedLeastSquares (diagnosis/diagnose_columns.h) against its definition: the least sum of
// squares over every choice of constrained coefficients held at 0 (the rest fitted freely), among the
// choices whose fitted constrained coefficients are all >= 0 (Lawson & Hanson 1974, ch. 23: the
// optimum is such a choice).
#include "diagnosis/diagnose_columns.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/QR>

namespace exotwin {
namespace {

TEST(SignConstrainedLeastSquares, IsTheBestFeasibleSubsetFit) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0, 1);
  const int rows = 60, cols = 7;
  for (int trial = 0; trial < 40; ++trial) {
    Eigen::MatrixXd X(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int k = 0; k < cols; ++k) X(i, k) = n01(rng) + (k == 3 ? 0.8 * X(i, 2) : 0.0);  // two collinear columns
    Eigen::VectorXd y(rows);
    for (int i = 0; i < rows; ++i) y[i] = -1.5 * X(i, 0) + 0.7 * X(i, 1) - 0.4 * X(i, 2) + 0.3 * n01(rng);
    std::vector<bool> nonneg(cols, false);
    for (int k : {0, 2, 3, 5}) nonneg[k] = true;  // column 0's true coefficient is negative
    const Eigen::VectorXd x = SignConstrainedLeastSquares(X, y, nonneg);
    for (int k = 0; k < cols; ++k) {
      if (nonneg[k]) {
        EXPECT_GE(x[k], 0.0) << "trial " << trial << " column " << k;
      }
    }
    const double sse = (X * x - y).squaredNorm();
    // Reference: every subset of the constrained columns held at 0, the others by least squares.
    const int constrained[4] = {0, 2, 3, 5};
    double best = INFINITY;
    for (int mask = 0; mask < 16; ++mask) {
      std::vector<int> keep;
      for (int k = 0; k < cols; ++k) {
        bool zero = false;
        for (int c = 0; c < 4; ++c) zero = zero || (constrained[c] == k && (mask >> c & 1));
        if (!zero) keep.push_back(k);
      }
      Eigen::MatrixXd Xs(rows, static_cast<Eigen::Index>(keep.size()));
      for (size_t a = 0; a < keep.size(); ++a) Xs.col(static_cast<Eigen::Index>(a)) = X.col(keep[a]);
      const Eigen::VectorXd xs = Xs.colPivHouseholderQr().solve(y);
      bool feasible = true;
      for (size_t a = 0; a < keep.size(); ++a) feasible = feasible && (!nonneg[keep[a]] || xs[a] >= 0);
      if (feasible) best = std::min(best, (Xs * xs - y).squaredNorm());
    }
    EXPECT_NEAR(sse, best, 1e-6 * best) << "trial " << trial;
  }
  // No constraint: the ordinary least squares.
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(30, 3);
  Eigen::VectorXd y = Eigen::VectorXd::Random(30);
  const Eigen::VectorXd ls = X.colPivHouseholderQr().solve(y);
  EXPECT_LT((SignConstrainedLeastSquares(X, y, {false, false, false}) - ls).norm(), 1e-6);
}

}  // namespace
}  // namespace exotwin
