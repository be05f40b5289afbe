// Stage 3d of the torque fit (diagnose.cc): every record's ceiling and its null level.
#include <set>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "diagnosis/fit_families.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/diagnose_select.h"

namespace exotwin {

namespace {

constexpr double kNullShifts[] = {0.2, 0.35, 0.5, 0.65, 0.8};

}  // namespace

std::vector<CeilingScores> Ceilings(const std::vector<ColumnBank>& banks, const double w[2]) {
  std::vector<CeilingScores> out(banks.size());
  for (size_t r = 0; r < banks.size(); ++r) {
    const ColumnBank& b = banks[r];
    std::vector<int> sign(static_cast<size_t>(b.X.cols()), 0);
    for (const Candidate& c : b.candidates)
      if (FitFamilyOf(c.name).ceiling_sign > 0) sign[static_cast<size_t>(c.cols[0])] = 1;
    // The normal equations of the columns this record moves (a column of zeros, e.g. a held hip's,
    // stays at 0), diagonal regularized by 1e-6 of itself: collinear candidates (the kitchen sink of
    // one record) pass SolveSigned's conditioning test (1e-8 of the largest
    // eigenvalue of the unit-diagonal Gram) at a cost of the order of 1e-6 of the fit.
    // All columns' Gram at once (blocked, one pass over X), then the live columns' part.
    Eigen::MatrixXd G_all = Eigen::MatrixXd::Zero(b.X.cols(), b.X.cols());
    G_all.selfadjointView<Eigen::Lower>().rankUpdate(b.X.transpose());
    const Eigen::VectorXd h_all = b.X.transpose() * b.r;
    std::vector<int> live;
    for (Eigen::Index k = 0; k < b.X.cols(); ++k)
      if (G_all(k, k) > 0) live.push_back(static_cast<int>(k));
    Eigen::MatrixXd G(live.size(), live.size());
    Eigen::VectorXd h(live.size());
    std::vector<int> live_sign(live.size());
    for (size_t a = 0; a < live.size(); ++a) {
      h[a] = h_all[live[a]];
      live_sign[a] = sign[static_cast<size_t>(live[a])];
      for (size_t c = a; c < live.size(); ++c) G(a, c) = G(c, a) = G_all(std::max(live[a], live[c]), std::min(live[a], live[c]));
    }
    G.diagonal() += 1e-6 * G.diagonal();
    Eigen::VectorXd x_live, x = Eigen::VectorXd::Zero(b.X.cols());
    // With the ridge the unit-diagonal Gram's smallest eigenvalue is >= 1e-6 and its largest <= its
    // column count, so SolveSigned's test passes for up to 100 columns; beyond that a ceiling of 0 %
    // would be a false bound, so it is an error, not a score.
    if (!live.empty() && !SolveSigned(G, h, live_sign, &x_live))
      throw std::logic_error("diagnose: the ceiling of record " + std::to_string(r) + " (" +
                             std::to_string(live.size()) + " candidate columns) is too ill-conditioned to solve");
    for (size_t a = 0; a < live.size(); ++a) x[live[a]] = x_live[static_cast<Eigen::Index>(a)];
    const Eigen::VectorXd e = b.r - b.X * x;
    const Eigen::Index m = static_cast<Eigen::Index>(b.sample.size());
    // The null level: the same normal equations against the shifted residuals (all shifts in one
    // pass over X).
    constexpr Eigen::Index S = static_cast<Eigen::Index>(std::size(kNullShifts));
    Eigen::MatrixXd RS(b.r.size(), S), XS = Eigen::MatrixXd::Zero(b.X.cols(), S);
    for (Eigen::Index s = 0; s < S; ++s) {
      const Eigen::Index k = static_cast<Eigen::Index>(kNullShifts[s] * static_cast<double>(m));
      for (Eigen::Index j = 0; j < 2; ++j)
        for (Eigen::Index i = 0; i < m; ++i) RS(j * m + i, s) = b.r[j * m + (i + k) % m];
    }
    const Eigen::MatrixXd HS = b.X.transpose() * RS;
    for (Eigen::Index s = 0; s < S; ++s) {
      Eigen::VectorXd hs(live.size()), xs_live;
      for (size_t a = 0; a < live.size(); ++a) hs[a] = HS(live[a], s);
      if (!live.empty() && !SolveSigned(G, hs, live_sign, &xs_live))
        throw std::logic_error("diagnose: the null ceiling of record " + std::to_string(r) + " is too ill-conditioned to solve");
      for (size_t a = 0; a < live.size(); ++a) XS(live[a], s) = xs_live[static_cast<Eigen::Index>(a)];
    }
    RS.noalias() -= b.X * XS;  // the shifted residuals' errors
    double null_sse[2] = {0, 0};
    for (Eigen::Index s = 0; s < S; ++s)
      for (int j = 0; j < 2; ++j) null_sse[j] += RS.col(s).segment(j * m, m).squaredNorm() / static_cast<double>(S);
    for (int j = 0; j < 2; ++j) {
      if (!(w[j] > 0) || m == 0) continue;
      const double before = b.r.segment(j * m, m).squaredNorm() / (w[j] * w[j]);
      const double after = e.segment(j * m, m).squaredNorm() / (w[j] * w[j]);
      out[r].ceiling[j] = ScoreOf(before, after, static_cast<double>(m));
      out[r].null[j] = ScoreOf(before, null_sse[j] / (w[j] * w[j]), static_cast<double>(m));
    }
  }
  return out;
}

}  // namespace exotwin
