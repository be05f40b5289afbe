#include "diagnosis/black_box.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "core/parallel_for.h"
#include "core/rng.h"

namespace exotwin {

namespace {
constexpr Eigen::Index kBlockRows = 1024;  // fit rows whose features are formed at a time
}  // namespace

Eigen::MatrixXd BlackBox::Features(const Eigen::MatrixXd& X, double length) const {
  const Eigen::Index d = X.cols(), D = W_.rows();
  Eigen::MatrixXd Z(X.rows(), d);
  for (Eigen::Index c = 0; c < d; ++c) Z.col(c) = (X.col(c).array() - mean_[c]) * inv_sd_[c];
  Eigen::MatrixXd F(X.rows(), d + D);
  F.leftCols(d) = Z;
  F.rightCols(D).noalias() = Z * (W_.transpose() / length);
  const double scale = std::sqrt(2.0 / static_cast<double>(D));
  for (Eigen::Index k = 0; k < D; ++k)
    F.col(d + k) = scale * (F.col(d + k).array() + b_[k]).cos();
  return F;
}

BlackBox BlackBox::Fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const std::vector<bool>& validation,
                       const BlackBoxOptions& opt) {
  const Eigen::Index n = X.rows(), d = X.cols();
  if (Y.rows() != n || static_cast<Eigen::Index>(validation.size()) != n || n < 2 || d < 1 || opt.features < 1 ||
      opt.bandwidths.empty() || opt.ridges.empty())
    throw std::invalid_argument("BlackBox::Fit: rows of X, Y and validation differ, or empty options");
  Eigen::Index nv = 0;
  for (bool v : validation) nv += v;
  if (nv == 0 || nv == n) throw std::invalid_argument("BlackBox::Fit: expected both fit and validation rows");
  BlackBox bb;
  bb.mean_ = X.colwise().mean().transpose();
  bb.inv_sd_.resize(d);
  for (Eigen::Index c = 0; c < d; ++c) {
    const double sd = std::sqrt((X.col(c).array() - bb.mean_[c]).square().mean());
    bb.inv_sd_[c] = sd > 1e-12 * (std::abs(bb.mean_[c]) + 1e-300) ? 1 / sd : 0.0;
  }
  NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> rng(opt.seed);
  bb.W_.resize(opt.features, d);
  bb.b_.resize(opt.features);
  for (Eigen::Index k = 0; k < opt.features; ++k) {
    for (Eigen::Index c = 0; c < d; ++c) bb.W_(k, c) = rng.Normal();
    bb.b_[k] = 2 * M_PI * rng.Uniform();
  }
  bb.y_mean_ = Y.colwise().mean();
  const Eigen::MatrixXd Yc = Y.rowwise() - bb.y_mean_;
  const Eigen::Index C = Y.cols();
  bb.bandwidth_.assign(static_cast<size_t>(C), 0);
  bb.ridge_.assign(static_cast<size_t>(C), 0);
  bb.length_.assign(static_cast<size_t>(C), 0);
  bb.coef_.assign(static_cast<size_t>(C), Eigen::VectorXd());
  std::vector<double> best(static_cast<size_t>(C), std::numeric_limits<double>::infinity());
  // Fit and validation rows' features per length scale; the Gram of each part. The length scales
  // on up to opt.threads threads: each one's choice of ridge per column (the first least validation
  // error in the order of opt.ridges) and its refit, then the first least over the length scales in
  // their order (the same choice as one loop over both in that order).
  std::vector<Eigen::Index> fit_rows, val_rows;
  for (Eigen::Index i = 0; i < n; ++i) (validation[static_cast<size_t>(i)] ? val_rows : fit_rows).push_back(i);
  const Eigen::MatrixXd Xf = X(fit_rows, Eigen::all), Xv = X(val_rows, Eigen::all);
  const Eigen::MatrixXd Yf = Yc(fit_rows, Eigen::all), Yv = Yc(val_rows, Eigen::all);
  const double dim_scale = std::sqrt(static_cast<double>(d));
  struct Choice {
    std::vector<double> sse, ridge;
    std::vector<Eigen::VectorXd> coef;
  };
  std::vector<Choice> per_length(opt.bandwidths.size());
  ParallelFor(opt.bandwidths.size(), opt.threads, [&](size_t l) {
    const double length = opt.bandwidths[l] * dim_scale;
    Choice& ch = per_length[l];
    ch.sse.assign(static_cast<size_t>(C), std::numeric_limits<double>::infinity());
    ch.ridge.assign(static_cast<size_t>(C), 0);
    ch.coef.assign(static_cast<size_t>(C), Eigen::VectorXd());
    // The fit rows' Gram and moment in blocks of rows (their features are never held whole: memory).
    const Eigen::MatrixXd Fv = bb.Features(Xv, length);
    const Eigen::Index p = Fv.cols();
    Eigen::MatrixXd Gf = Eigen::MatrixXd::Zero(p, p), Gv = Eigen::MatrixXd::Zero(p, p);
    Eigen::MatrixXd hf = Eigen::MatrixXd::Zero(p, C);
    for (Eigen::Index a = 0; a < Xf.rows(); a += kBlockRows) {
      const Eigen::Index m = std::min(kBlockRows, Xf.rows() - a);
      const Eigen::MatrixXd Ff = bb.Features(Xf.middleRows(a, m), length);
      Gf.selfadjointView<Eigen::Lower>().rankUpdate(Ff.transpose());
      hf.noalias() += Ff.transpose() * Yf.middleRows(a, m);
    }
    Gv.selfadjointView<Eigen::Lower>().rankUpdate(Fv.transpose());
    Gf = Gf.selfadjointView<Eigen::Lower>();
    Gv = Gv.selfadjointView<Eigen::Lower>();
    const Eigen::MatrixXd hv = Fv.transpose() * Yv;
    const double diag = (Gf + Gv).diagonal().mean();
    for (double rg : opt.ridges) {
      Eigen::MatrixXd A = Gf;
      A.diagonal().array() += rg * diag;
      const Eigen::MatrixXd c = A.ldlt().solve(hf);
      const Eigen::MatrixXd err = Yv - Fv * c;
      for (Eigen::Index k = 0; k < C; ++k) {
        const double sse = err.col(k).squaredNorm();
        if (sse < ch.sse[static_cast<size_t>(k)]) ch.sse[static_cast<size_t>(k)] = sse, ch.ridge[static_cast<size_t>(k)] = rg;
      }
    }
    // The refit on every row with each column's choice (one factorization per ridge chosen).
    for (Eigen::Index k = 0; k < C; ++k) {
      if (!ch.coef[static_cast<size_t>(k)].size() && std::isfinite(ch.sse[static_cast<size_t>(k)])) {
        const double rg = ch.ridge[static_cast<size_t>(k)];
        Eigen::MatrixXd All = Gf + Gv;
        All.diagonal().array() += rg * diag;
        const Eigen::LDLT<Eigen::MatrixXd> ldlt(All);
        for (Eigen::Index k2 = k; k2 < C; ++k2)
          if (ch.ridge[static_cast<size_t>(k2)] == rg && std::isfinite(ch.sse[static_cast<size_t>(k2)]))
            ch.coef[static_cast<size_t>(k2)] = ldlt.solve(hf.col(k2) + hv.col(k2));
      }
    }
  });
  for (size_t l = 0; l < opt.bandwidths.size(); ++l)
    for (size_t k = 0; k < static_cast<size_t>(C); ++k) {
      if (!(per_length[l].sse[k] < best[k])) continue;
      best[k] = per_length[l].sse[k];
      bb.bandwidth_[k] = opt.bandwidths[l], bb.ridge_[k] = per_length[l].ridge[k];
      bb.length_[k] = opt.bandwidths[l] * dim_scale;
      bb.coef_[k] = std::move(per_length[l].coef[k]);
    }
  return bb;
}

Eigen::MatrixXd BlackBox::Predict(const Eigen::MatrixXd& X) const {
  const Eigen::Index C = static_cast<Eigen::Index>(coef_.size());
  Eigen::MatrixXd out(X.rows(), C);
  std::vector<bool> done(static_cast<size_t>(C), false);
  for (Eigen::Index k = 0; k < C; ++k) {
    if (done[static_cast<size_t>(k)]) continue;
    const double length = length_[static_cast<size_t>(k)];
    // The features once for every column of this length scale, in blocks of rows.
    for (Eigen::Index a = 0; a < X.rows(); a += kBlockRows) {
      const Eigen::Index m = std::min(kBlockRows, X.rows() - a);
      const Eigen::MatrixXd F = Features(X.middleRows(a, m), length);
      for (Eigen::Index k2 = k; k2 < C; ++k2)
        if (length_[static_cast<size_t>(k2)] == length)
          out.col(k2).segment(a, m) = (F * coef_[static_cast<size_t>(k2)]).array() + y_mean_[k2];
    }
    for (Eigen::Index k2 = k; k2 < C; ++k2) done[static_cast<size_t>(k2)] = done[static_cast<size_t>(k2)] || length_[static_cast<size_t>(k2)] == length;
  }
  return out;
}

}  // namespace exotwin
