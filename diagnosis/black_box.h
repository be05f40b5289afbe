// A black-box regression for diagnose's ceiling (DESIGN.md "Terms beyond the table": `ceiling`): how
// much of a residual a flexible function of the motion could still explain, beside what the named
// model explains.
//
// Kernel ridge regression on random Fourier features (Rahimi & Recht 2007): the inputs standardized
// (train rows' mean and standard deviation; a constant input is dropped), then the features
//   phi(x) = [x, sqrt(2 / D) cos(W x / l + b)],  W_ij ~ N(0, 1), b_i ~ U[0, 2 pi), D features,
// which approximate the Gaussian kernel exp(-|x - x'|^2 / (2 l^2)) plus a linear one; the output's
// train mean is removed and the ridge solution c = (Phi' Phi + lambda I)^-1 Phi' y fitted. The length
// scale l (BlackBoxOptions::bandwidths times sqrt of the input dimension) and lambda
// (BlackBoxOptions::ridges times the mean of Phi' Phi's diagonal) are chosen per output column by
// the least squared error on the validation rows of a fit on the other rows, then refitted on all
// rows. Deterministic: W and b from core/rng.h with BlackBoxOptions::seed (one draw of W scaled by
// each l), so the same seed and rows give the same bits.
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace exotwin {

struct BlackBoxOptions {
  uint64_t seed = 1;
  int features = 256;                                    // D, random Fourier features
  std::vector<double> bandwidths = {0.35, 0.7, 1.4};     // l / sqrt(input dimension)
  std::vector<double> ridges = {1e-7, 1e-5, 1e-3, 1e-1, 10};  // lambda / mean diag(Phi' Phi)
  int threads = 1;  // the length scales fitted side by side (the same bits on any count)
};

class BlackBox {
 public:
  // Fits every column of Y (rows as X's) on X's rows; rows with validation[i] true choose the length
  // scale and ridge (at least one row of each kind). The columns are independent fits sharing the
  // features and their Gram matrices: several targets on the same rows cost about one. Throws std::invalid_argument on mismatched sizes.
  static BlackBox Fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const std::vector<bool>& validation,
                      const BlackBoxOptions& opt = {});
  // The fitted function at X's rows (inputs as in Fit): one column per column of Y.
  Eigen::MatrixXd Predict(const Eigen::MatrixXd& X) const;
  // The chosen length scale (l / sqrt(dimension)) and ridge of output column k.
  double bandwidth(int k) const { return bandwidth_[static_cast<size_t>(k)]; }
  double ridge(int k) const { return ridge_[static_cast<size_t>(k)]; }

 private:
  Eigen::MatrixXd Features(const Eigen::MatrixXd& X, double length) const;
  Eigen::VectorXd mean_, inv_sd_;  // input standardization (inv_sd_ 0: a constant input)
  Eigen::MatrixXd W_;              // D x inputs, N(0, 1)
  Eigen::VectorXd b_;              // D
  Eigen::RowVectorXd y_mean_;
  std::vector<double> bandwidth_, ridge_, length_;
  std::vector<Eigen::VectorXd> coef_;  // per output column
};

}  // namespace exotwin
