// The motion fit's numerics (motion_fit.h "Method", steps 2-4): the weighted residual and Jacobian of
// the fit rows, projected Levenberg-Marquardt inside the box with a dead band's probes, the secant
// refinement of one parameter, and the values of each record left out.
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "diagnosis/motion_fit.h"
#include "diagnosis/motion_fit_internal.h"
#include "dsp/statistics.h"
#include "model/effect_families.h"

namespace exotwin {
namespace motion {

double Cost(const MotionProblem& P, const MotionProblem::Rollout& ro, Part part) {
  if (!ro.ok) return INFINITY;
  double s[2];
  P.Sse(ro, part, s);
  return s[0] + s[1];
}

std::vector<Eigen::Index> PartRows(const MotionProblem& P, Part part) {
  std::vector<Eigen::Index> out;
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size();
    for (int j = 0; j < 2; ++j) {
      if (P.weight(j) == 0) continue;
      const size_t k0 = part == Part::kHeldOut ? P.fit_rows(r) : 0, k1 = part == Part::kFit ? P.fit_rows(r) : m;
      for (size_t k = k0; k < k1; ++k) out.push_back(off + static_cast<Eigen::Index>(j * m + k));
    }
    off += static_cast<Eigen::Index>(2 * m);
  }
  return out;
}

Eigen::VectorXd WeightedResidual(const MotionProblem& P, const MotionProblem::Rollout& ro,
                                 const std::vector<Eigen::Index>& idx) {
  Eigen::VectorXd all;
  std::vector<double> w;
  Eigen::Index total = 0;
  for (size_t r = 0; r < P.records(); ++r) total += P.measured(r).size();
  all.resize(total);
  Eigen::VectorXd wv(total);
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const Eigen::Index m2 = P.measured(r).size();
    all.segment(off, m2) = P.measured(r) - ro.q[r];
    wv.segment(off, m2 / 2).setConstant(P.weight(r, 0));
    wv.segment(off + m2 / 2, m2 / 2).setConstant(P.weight(r, 1));
    off += m2;
  }
  Eigen::VectorXd e(static_cast<Eigen::Index>(idx.size()));
  for (size_t k = 0; k < idx.size(); ++k) e[static_cast<Eigen::Index>(k)] = wv[idx[k]] * all[idx[k]];
  return e;
}

Eigen::VectorXd RowWeights(const MotionProblem& P) {
  Eigen::Index total = 0;
  for (size_t r = 0; r < P.records(); ++r) total += P.measured(r).size();
  Eigen::VectorXd wv(total);
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const Eigen::Index m2 = P.measured(r).size();
    wv.segment(off, m2 / 2).setConstant(P.weight(r, 0));
    wv.segment(off + m2 / 2, m2 / 2).setConstant(P.weight(r, 1));
    off += m2;
  }
  return wv;
}

double ResidualAutocorrelation(const MotionProblem& P, const MotionProblem::Rollout& ro, double window_rows) {
  double tau = 1;
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
    for (int j = 0; j < 2; ++j) {
      if (P.weight(j) == 0 || mf < 8) continue;
      std::vector<double> e(mf);
      for (size_t k = 0; k < mf; ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(j * m + k);
        e[k] = P.measured(r)[i] - ro.q[r][i];
      }
      tau = std::max(tau, AutocorrelationLength(e.data(), e.size()));
    }
  }
  return std::min(tau, std::max(1.0, window_rows));
}

Eigen::MatrixXd WeightedFitJacobian(const MotionProblem& P, const Eigen::VectorXd& theta, const MotionProblem::Rollout& at,
                                    const std::vector<int>& cols) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  const Eigen::VectorXd wv = RowWeights(P);
  const Eigen::MatrixXd Jall = P.Jacobian(theta, at, cols, Part::kFit);
  Eigen::MatrixXd J(static_cast<Eigen::Index>(idx.size()), Jall.cols());
  for (size_t k = 0; k < idx.size(); ++k) J.row(static_cast<Eigen::Index>(k)) = wv[idx[k]] * Jall.row(idx[k]);
  return J;
}

std::vector<Eigen::VectorXd> LeftOutThetas(const MotionProblem& P, const Eigen::VectorXd& theta,
                                           const std::vector<int>& cols, const Eigen::MatrixXd& J,
                                           const Eigen::VectorXd& e, int* unidentifiable) {
  *unidentifiable = -1;
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  std::vector<size_t> owner(idx.size());
  Eigen::Index off = 0;
  size_t rec = 0;
  for (size_t k = 0; k < idx.size(); ++k) {
    while (idx[k] >= off + P.measured(rec).size()) off += P.measured(rec).size(), ++rec;
    owner[k] = rec;
  }
  std::vector<Eigen::VectorXd> out;
  const Eigen::Index p = static_cast<Eigen::Index>(cols.size());
  for (size_t r = 0; r < P.records(); ++r) {
    Eigen::VectorXd x = theta;
    if (p > 0) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(p);
      for (size_t k = 0; k < owner.size(); ++k) {
        if (owner[k] == r) continue;
        const Eigen::Index i = static_cast<Eigen::Index>(k);
        A.noalias() += J.row(i).transpose() * J.row(i);
        g.noalias() += J.row(i).transpose() * e[i];
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
      const Eigen::VectorXd d = ldlt.solve(g);
      if (ldlt.info() != Eigen::Success || !d.allFinite() || !(A.diagonal().minCoeff() > 0)) {
        *unidentifiable = static_cast<int>(r);
        return {};
      }
      for (Eigen::Index c = 0; c < p; ++c) {
        const int k = cols[static_cast<size_t>(c)];
        x[k] = std::clamp(theta[k] + d[c], P.lower(k), P.upper(k));
      }
    }
    out.push_back(x);
  }
  return out;
}

Refined Refine(const MotionProblem& P, const std::vector<int>& cols, const std::vector<Eigen::VectorXd>& starts,
               int iterations, bool jacobian) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  const Eigen::VectorXd wv = RowWeights(P);
  auto Clamp = [&](Eigen::VectorXd x) {
    for (int k : cols) x[k] = std::clamp(x[k], P.lower(k), P.upper(k));
    return x;
  };
  std::vector<Eigen::VectorXd> xs;
  for (const auto& s : starts) xs.push_back(Clamp(s));
  std::vector<MotionProblem::Rollout> ro = P.SimulateAll(xs, Part::kFit);
  size_t best = 0;
  for (size_t k = 1; k < xs.size(); ++k)
    if (Cost(P, ro[k], Part::kFit) < Cost(P, ro[best], Part::kFit)) best = k;
  Refined R;
  R.theta = xs[best];
  MotionProblem::Rollout at = ro[best];
  R.cost = Cost(P, at, Part::kFit);
  if (!std::isfinite(R.cost)) return R;
  auto WeightedJ = [&](const MotionProblem::Rollout& a, const Eigen::VectorXd& theta) {
    return WeightedFitJacobian(P, theta, a, cols);
  };
  double lambda = 1e-3;
  bool fresh = false;
  // The Levenberg-Marquardt iterations from R.theta (its rollout `at`).
  auto Lm = [&]() {
    for (int it = 0; it < iterations; ++it) {
      R.J = WeightedJ(at, R.theta);
      R.e = WeightedResidual(P, at, idx);
      fresh = true;
      const Eigen::MatrixXd A = R.J.transpose() * R.J;
      const Eigen::VectorXd g = R.J.transpose() * R.e;
      const Eigen::VectorXd D = A.diagonal().cwiseMax(1e-12 * std::max(A.diagonal().maxCoeff(), 1e-300));
      bool improved = false;
      const double before = R.cost;
      for (int trial = 0; trial < 6 && !improved; ++trial) {
        Eigen::MatrixXd Al = A;
        Al.diagonal() += lambda * D;
        const Eigen::VectorXd d = Al.ldlt().solve(g);
        Eigen::VectorXd x = R.theta;
        for (size_t c = 0; c < cols.size(); ++c) x[cols[c]] += d[static_cast<Eigen::Index>(c)];
        x = Clamp(x);
        if ((x - R.theta).norm() == 0) break;
        // The decrease the linear model predicts for the clamped step, |e|^2 - |e - J dx|^2: below the
        // stopping rule's 1e-5 of the cost, no rollout can meet the rule (converged).
        Eigen::VectorXd dx(static_cast<Eigen::Index>(cols.size()));
        for (size_t c = 0; c < cols.size(); ++c) dx[static_cast<Eigen::Index>(c)] = x[cols[c]] - R.theta[cols[c]];
        if (2 * dx.dot(g) - dx.dot(A * dx) < 1e-5 * R.cost) break;
        MotionProblem::Rollout rx = P.Simulate(x, Part::kFit);
        const double cx = Cost(P, rx, Part::kFit);
        if (cx < R.cost) {
          R.theta = x, R.cost = cx, at = std::move(rx);
          lambda = std::max(lambda / 3, 1e-9);
          improved = true, fresh = false;
        } else {
          lambda *= 5;
        }
      }
      if (!improved || before - R.cost < 1e-5 * before) break;
    }
  };
  Lm();
  // A dead band's cost is rough below the scale of its effect (a closure moves by a whole physics
  // step as the band changes by a fraction of a step's travel: notches of a few % within 1e-4 rad),
  // where the local step above sees a minimum that is none. Probes at a quarter and a half of the
  // band's size (at least its secant step) on either side, the other values held; where one is
  // lower the refinement restarts there (kMotionBandProbes rounds at most).
  for (int round = 0; round < kMotionBandProbes; ++round) {
    std::vector<Eigen::VectorXd> probes;
    for (int k : cols) {
      const EffectFamily* f = FindFamily(P.kind(k));  // a dead band's parameter
      if (!f || f->carrier != PlantCarrier::kDeadBandHinge) continue;
      const double size = std::max(R.theta[k], P.step(k));
      for (double f : {-0.5, -0.25, 0.25, 0.5}) {
        Eigen::VectorXd x = R.theta;
        x[k] = std::clamp(x[k] + f * size, P.lower(k), P.upper(k));
        if (x[k] != R.theta[k]) probes.push_back(x);
      }
    }
    if (probes.empty()) break;
    std::vector<MotionProblem::Rollout> pr = P.SimulateAll(probes, Part::kFit);
    size_t b = 0;
    double cb = Cost(P, pr[0], Part::kFit);
    for (size_t k = 1; k < probes.size(); ++k) {
      const double ck = Cost(P, pr[k], Part::kFit);
      if (ck < cb) cb = ck, b = k;
    }
    if (!(cb < R.cost)) break;
    R.theta = probes[b], R.cost = cb, at = std::move(pr[b]);
    fresh = false, lambda = 1e-3;
    Lm();
  }
  if (!fresh && jacobian) {
    R.J = WeightedJ(at, R.theta);
    R.e = WeightedResidual(P, at, idx);
  }
  return R;
}

double RefineOne(const MotionProblem& P, int k, const Eigen::VectorXd& theta, const MotionProblem::Rollout& base,
                 double start, int iterations) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  // e = w (q - qsim) on the fit rows, so the weighted derivative of qsim is -de/dx: the secant
  // (e_prev - e_cur) / (x_cur - x_prev).
  double x_prev = theta[k], x_cur = std::clamp(start, P.lower(k), P.upper(k));
  if (!base.ok || x_cur == x_prev) return x_prev;
  Eigen::VectorXd e_prev = WeightedResidual(P, base, idx);
  double best_x = x_prev, best_cost = e_prev.squaredNorm();
  Eigen::VectorXd x = theta;
  x[k] = x_cur;
  const MotionProblem::Rollout ro = P.Simulate(x, Part::kFit);
  if (!ro.ok) return best_x;
  Eigen::VectorXd e_cur = WeightedResidual(P, ro, idx);
  double cost_cur = e_cur.squaredNorm();
  if (cost_cur < best_cost) best_x = x_cur, best_cost = cost_cur;
  for (int it = 1; it < iterations; ++it) {
    const Eigen::VectorXd Jw = (e_prev - e_cur) / (x_cur - x_prev);
    const double a = Jw.squaredNorm();
    if (!(a > 0)) break;
    // Gauss-Newton on the secant, e(x) ~ e_cur - Jw (x - x_cur), clamped to the box.
    const double x_new = std::clamp(x_cur + Jw.dot(e_cur) / a, P.lower(k), P.upper(k));
    const double dx = x_new - x_cur;
    if (dx == 0 || 2 * dx * Jw.dot(e_cur) - a * dx * dx < 1e-5 * cost_cur) break;  // converged (the stopping rule)
    x[k] = x_new;
    const MotionProblem::Rollout rn = P.Simulate(x, Part::kFit);
    if (!rn.ok) break;
    Eigen::VectorXd e_new = WeightedResidual(P, rn, idx);
    const double cost_new = e_new.squaredNorm();
    if (cost_new < best_cost) best_x = x_new, best_cost = cost_new;
    x_prev = x_cur, e_prev = std::move(e_cur);
    x_cur = x_new, e_cur = std::move(e_new), cost_cur = cost_new;
  }
  return best_x;
}

}  // namespace motion
}  // namespace exotwin
