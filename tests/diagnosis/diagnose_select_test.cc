// Sign-constrained least squares (diagnosis/diagnose_select.h SolveSigned, FitColsSigned) against
// an independent reference: every choice of the constrained variables held at zero, each solved
// unconstrained, the feasible one of least cost (the problem is convex: that is the optimum).
#include "diagnosis/diagnose_select.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/rng.h"
#include "diagnosis/effects.h"
#include "formats/model_file.h"

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

// The physical scale's angle RMS and strap torque RMS (ScaleOf) on a gait-like sinusoid of whole
// periods, against closed forms and a direct sum; the range (Plausible) of a strap at the angle's
// materiality, kMinTorqueShare of its RMS about the mean (DESIGN.md's table).
TEST(PhysicalScale, StrapsBelowTheAnglesMaterialityAreOutsideTheirRange) {
  const LegParams params = ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml");
  ASSERT_TRUE(params.human);
  Kinematics kin;
  const double A[2] = {0.35, 0.5}, w = 2 * M_PI;  // 1 Hz, 4 whole periods at 1 kHz
  std::vector<double> tau[2];
  for (int i = 0; i < 4000; ++i) {
    const double t = 0.001 * i;
    kin.t.push_back(t);
    for (int j = 0; j < 2; ++j) {
      const double ph = j == 0 ? 0.0 : 1.0, mean = j == 0 ? 0.1 : -0.6;
      kin.q[j].push_back(mean + A[j] * std::sin(w * t + ph));
      kin.qd[j].push_back(A[j] * w * std::cos(w * t + ph));
      kin.qdd[j].push_back(-A[j] * w * w * std::sin(w * t + ph));
      tau[j].push_back(1.0);
    }
  }
  const PhysicalScale s = ScaleOf(params, {{&kin, {&tau[0], &tau[1]}}});
  LegParams rigid = params;
  rigid.effects.clear();
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(s.q_rms[j], A[j] / std::sqrt(2.0), 1e-9) << j;
    double sum = 0, n = 0;  // ScaleOf's stride: every sample below 4000 per record
    for (size_t i = 0; i < kin.t.size(); ++i) {
      const Eigen::Vector2d q(kin.q[0][i], kin.q[1][i]), qd(kin.qd[0][i], kin.qd[1][i]), qdd(kin.qdd[0][i], kin.qdd[1][i]);
      sum += std::pow(CompliantPartTorque(rigid, q, qd, qdd)[j], 2), n += 1;
    }
    EXPECT_NEAR(s.tau_C_rms[j], std::sqrt(sum / n), 1e-9 * (1 + s.tau_C_rms[j])) << j;
  }
  // At the knee: the floor kMinTorqueShare q_rms, a strap 10 % either side of it.
  const double floor = kMinTorqueShare * s.q_rms[1], k_floor = s.tau_C_rms[1] / floor;
  auto effect = [](const std::string& name, double v) {
    DiagnosedEffect d;
    d.effect.name = name, d.effect.joint = "knee", d.effect.value = v;
    return d;
  };
  std::string why;
  EXPECT_FALSE(Plausible(effect("series_compliance", 1.1 * k_floor), s, &why));
  EXPECT_NE(why.find("materiality"), std::string::npos) << why;
  // Just inside the floor (a strap that stiff resonates far above this 1 Hz motion).
  EXPECT_TRUE(Plausible(effect("series_compliance", 0.9 * k_floor), s, &why)) << why;
  // The straps (300-1500 N m/rad) on this motion: far above the floor.
  EXPECT_GT(k_floor, 3 * 1500.0);
}

// A dead band and a strap at one joint are one internal hinge too many for the forward plant
// (ToPlantEffects refuses the pair): the selection never names both there (issue 62's first defect:
// the torque fit could name both, and the extended twin then could not be simulated). At two joints
// they are two hinges, which the plant carries.
TEST(Conflicts, ADeadBandAndAStrapAtOneJointExcludeEachOther) {
  auto cand = [](const std::string& name, int joint, int col) {
    Candidate c;
    c.name = name, c.joint = joint, c.cols = {col};
    return c;
  };
  EXPECT_TRUE(Conflicts(cand("backlash", 1, 3), cand("series_compliance", 1, 4)));
  EXPECT_TRUE(Conflicts(cand("series_compliance", 0, 4), cand("backlash", 0, 3)));
  EXPECT_FALSE(Conflicts(cand("backlash", 1, 3), cand("series_compliance", 0, 4)));
  // The plant agrees: the pair at one joint is refused, at two joints carried.
  LegParams p;
  p.exo = {1.0, 0.3, 0.8, 0.3, 0.0, 0.0};
  Effect b, s;
  b.name = "backlash", b.joint = "knee", b.value = 0.01;
  s.name = "series_compliance", s.joint = "knee", s.value = 500;
  p.effects = {b, s};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
  p.effects[1].joint = "hip";
  EXPECT_NO_THROW(ToPlantEffects(p, "m.yaml"));
}

}  // namespace
}  // namespace exotwin
