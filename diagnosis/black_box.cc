#include "diagnosis/black_box.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "core/rng.h"

namespace exotwin {

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
  // Fit and validation rows' features per length scale; the Gram of each part.
  std::vector<Eigen::Index> fit_rows, val_rows;
  for (Eigen::Index i = 0; i < n; ++i) (validation[static_cast<size_t>(i)] ? val_rows : fit_rows).push_back(i);
  const Eigen::MatrixXd Xf = X(fit_rows, Eigen::all), Xv = X(val_rows, Eigen::all);
  const Eigen::MatrixXd Yf = Yc(fit_rows, Eigen::all), Yv = Yc(val_rows, Eigen::all);
  const double dim_scale = std::sqrt(static_cast<double>(d));
  for (double bw : opt.bandwidths) {
    const double length = bw * dim_scale;
    const Eigen::MatrixXd Ff = bb.Features(Xf, length), Fv = bb.Features(Xv, length);
    const Eigen::Index p = Ff.cols();
    Eigen::MatrixXd Gf = Eigen::MatrixXd::Zero(p, p), Gv = Eigen::MatrixXd::Zero(p, p);
    Gf.selfadjointView<Eigen::Lower>().rankUpdate(Ff.transpose());
    Gv.selfadjointView<Eigen::Lower>().rankUpdate(Fv.transpose());
    Gf = Gf.selfadjointView<Eigen::Lower>();
    Gv = Gv.selfadjointView<Eigen::Lower>();
    const Eigen::MatrixXd hf = Ff.transpose() * Yf, hv = Fv.transpose() * Yv;
    const double diag = (Gf + Gv).diagonal().mean();
    for (double rg : opt.ridges) {
      Eigen::MatrixXd A = Gf;
      A.diagonal().array() += rg * diag;
      const Eigen::MatrixXd c = A.ldlt().solve(hf);
      const Eigen::MatrixXd err = Yv - Fv * c;
      for (Eigen::Index k = 0; k < C; ++k) {
        const double sse = err.col(k).squaredNorm();
        if (!(sse < best[static_cast<size_t>(k)])) continue;
        best[static_cast<size_t>(k)] = sse;
        bb.bandwidth_[static_cast<size_t>(k)] = bw, bb.ridge_[static_cast<size_t>(k)] = rg;
        bb.length_[static_cast<size_t>(k)] = length;
        // The refit on every row with this choice.
        Eigen::MatrixXd All = Gf + Gv;
        All.diagonal().array() += rg * diag;
        bb.coef_[static_cast<size_t>(k)] = All.ldlt().solve(hf.col(k) + hv.col(k));
      }
    }
  }
  return bb;
}

Eigen::MatrixXd BlackBox::Predict(const Eigen::MatrixXd& X) const {
  const Eigen::Index C = static_cast<Eigen::Index>(coef_.size());
  Eigen::MatrixXd out(X.rows(), C);
  for (Eigen::Index k = 0; k < C; ++k) {
    const Eigen::MatrixXd F = Features(X, length_[static_cast<size_t>(k)]);
    out.col(k) = (F * coef_[static_cast<size_t>(k)]).array() + y_mean_[k];
  }
  return out;
}

}  // namespace exotwin
