// Sign-constrained least squares (diagnosis/diagnose_select.h SolveSigned, FitColsSigned) against
// an independent reference: every choice of the constrained variables held at zero, each solved
// unconstrained, the feasible one of least cost (the problem is convex: that is the optimum).
#include "diagnosis/diagnose_select.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <Eigen/Dense>

#include "core/rng.h"

namespace exotwin {
namespace {

double Cost(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  return x.dot(A * x) - 2 * b.dot(x);
}

// Brute force over the 2^k subsets of the constrained variables held at zero.
Eigen::VectorXd Enumerated(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<int>& sign) {
  const int n = static_cast<int>(b.size());
  std::vector<int> con;
  for (int i = 0; i < n; ++i)
    if (sign[i] != 0) con.push_back(i);
  Eigen::VectorXd best;
  double best_cost = 1e300;
  for (unsigned mask = 0; mask < (1u << con.size()); ++mask) {
    std::vector<int> p;
    for (int i = 0; i < n; ++i) {
      const auto it = std::find(con.begin(), con.end(), i);
      if (it == con.end() || !(mask >> (it - con.begin()) & 1u)) p.push_back(i);
    }
    Eigen::MatrixXd Ap(p.size(), p.size());
    Eigen::VectorXd bp(p.size());
    for (size_t a = 0; a < p.size(); ++a) {
      bp[static_cast<Eigen::Index>(a)] = b[p[a]];
      for (size_t c = 0; c < p.size(); ++c) Ap(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) = A(p[a], p[c]);
    }
    const Eigen::VectorXd xp = p.empty() ? Eigen::VectorXd() : Eigen::VectorXd(Ap.ldlt().solve(bp));
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    bool feasible = true;
    for (size_t a = 0; a < p.size(); ++a) {
      x[p[a]] = xp[static_cast<Eigen::Index>(a)];
      feasible &= sign[p[a]] * x[p[a]] >= 0;
    }
    if (feasible && Cost(A, b, x) < best_cost) best_cost = Cost(A, b, x), best = x;
  }
  return best;
}

TEST(SolveSigned, MatchesTheEnumeratedOptimum) {
  NormalRng<NormalPolar> rng(7);
  int held_somewhere = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 7, m = 40;
    Eigen::MatrixXd X(m, n);
    Eigen::VectorXd y(m);
    for (int i = 0; i < m; ++i) {
      y[i] = rng.Normal();
      for (int c = 0; c < n; ++c) X(i, c) = rng.Normal() + (c > 0 ? 0.6 * X(i, c - 1) : 0.0);  // correlated columns
    }
    const Eigen::MatrixXd A = X.transpose() * X;
    const Eigen::VectorXd b = X.transpose() * y;
    const std::vector<int> sign = {1, -1, 0, 1, 1, -1, 0};
    Eigen::VectorXd x;
    ASSERT_TRUE(SolveSigned(A, b, sign, &x));
    const Eigen::VectorXd ref = Enumerated(A, b, sign);
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(x[i], ref[i], 1e-9 * (1 + ref.cwiseAbs().maxCoeff())) << "trial " << trial << ", x" << i;
      EXPECT_GE(sign[i] * x[i], 0.0);
      held_somewhere += sign[i] != 0 && x[i] == 0;
    }
  }
  EXPECT_GT(held_somewhere, 100);  // the constraints were active, not only met by the free solution
}

TEST(SolveSigned, UnconstrainedSolutionWhenItKeepsTheSigns) {
  Eigen::MatrixXd A(2, 2);
  A << 2, 0.5, 0.5, 1;
  const Eigen::VectorXd truth = Eigen::Vector2d(3, -2);
  const Eigen::VectorXd b = A * truth;
  Eigen::VectorXd x;
  ASSERT_TRUE(SolveSigned(A, b, {1, -1}, &x));
  EXPECT_NEAR(x[0], 3, 1e-12);
  EXPECT_NEAR(x[1], -2, 1e-12);
  ASSERT_TRUE(SolveSigned(A, b, {1, 1}, &x));  // x1 >= 0: held at zero, x0 = b0 / A00
  EXPECT_EQ(x[1], 0.0);
  EXPECT_NEAR(x[0], b[0] / A(0, 0), 1e-12);
}

}  // namespace
}  // namespace exotwin
