// EMG-to-torque calibration (HJ15 eq. 23-28): see emg_calibration.h.
#include "emg/emg_calibration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "dsp/mvc.h"

namespace exotwin {

FitQuality Quality(const std::vector<double>& y, const std::vector<double>& yhat) {
  if (y.empty() || y.size() != yhat.size()) throw std::invalid_argument("Quality: sizes differ or empty");
  double mean = 0;
  for (double v : y) mean += v;
  mean /= y.size();
  double ss_res = 0, ss_tot = 0;
  for (size_t k = 0; k < y.size(); ++k) {
    ss_res += (y[k] - yhat[k]) * (y[k] - yhat[k]);
    ss_tot += (y[k] - mean) * (y[k] - mean);
  }
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  if (!(ss_tot > 0) || !(*hi > *lo)) throw std::invalid_argument("Quality: measured is constant");
  FitQuality q;
  q.r2 = 1 - ss_res / ss_tot;
  q.nrms_pct = 100 * std::sqrt(ss_res / y.size()) / (*hi - *lo);
  return q;
}

double RestLevel(const std::vector<double>& env, size_t a, size_t b) {
  if (!(b > a) || b > env.size()) throw std::invalid_argument("RestLevel: bad window");
  double s = 0;
  for (size_t k = a; k < b; ++k) s += env[k];
  return s / (b - a);
}

MuscleVec NormalizedEnvelope(const std::vector<std::vector<double>>& env, size_t k, const MuscleVec& rest,
                             const MuscleVec& mvc) {
  MuscleVec le;
  for (int c = 0; c < kNumMuscles; ++c) le[c] = dsp::NormalizeToMvc(env[c][k], rest[c], mvc[c]);
  return le;
}

double IsometricTorque(int joint, const MuscleVec& alpha, const MuscleVec& le) {
  double tau = 0;
  for (int m = 0; m < kNumMuscles; ++m) tau += ActionSign(MuscleAt(m), joint) * alpha[m] * le[m];
  return tau;
}

AlphaFit FitIsometricAlpha(int joint, const std::vector<MuscleVec>& le, const std::vector<double>& tau) {
  if (le.size() != tau.size() || le.empty()) throw std::invalid_argument("FitIsometricAlpha: sizes");
  std::vector<int> cols;
  for (int m = 0; m < kNumMuscles; ++m)
    if (ActionSign(MuscleAt(m), joint) != 0) cols.push_back(m);
  Eigen::MatrixXd A(le.size(), cols.size());
  Eigen::VectorXd b(le.size());
  for (size_t k = 0; k < le.size(); ++k) {
    for (size_t c = 0; c < cols.size(); ++c)
      A(k, c) = ActionSign(MuscleAt(cols[c]), joint) * le[k][cols[c]];
    b[k] = tau[k];
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);  // HJ15 eq. 25, unconstrained as the paper
  AlphaFit fit;
  for (size_t c = 0; c < cols.size(); ++c) fit.alpha[cols[c]] = x[c];
  std::vector<double> pred(le.size());
  for (size_t k = 0; k < le.size(); ++k) pred[k] = IsometricTorque(joint, fit.alpha, le[k]);
  fit.quality = Quality(tau, pred);
  return fit;
}

namespace {
void SplitEF(int joint, const MuscleVec& alpha, const MuscleVec& le, double& E, double& F) {
  E = F = 0;
  for (int m = 0; m < kNumMuscles; ++m) {
    const int s = ActionSign(MuscleAt(m), joint);
    if (s > 0) E += alpha[m] * le[m];
    if (s < 0) F += alpha[m] * le[m];
  }
}
}  // namespace

double DynamicTorque(int joint, const MuscleVec& alpha, double beta, double gamma, double theta_c,
                     const MuscleVec& le, double q, double qd) {
  double E, F;
  SplitEF(joint, alpha, le, E, F);
  const double d = beta * (q - theta_c) - gamma * qd;
  return E * (1 + d) - F * (1 - d);  // HJ15 eq. 26/27, no clamp (the paper's linear model)
}

BetaGammaFit FitDynamicBetaGamma(int joint, const MuscleVec& alpha, double theta_c,
                                 const std::vector<MuscleVec>& le, const std::vector<double>& q,
                                 const std::vector<double>& qd, const std::vector<double>& tau_M) {
  const size_t n = le.size();
  if (q.size() != n || qd.size() != n || tau_M.size() != n || n < 2)
    throw std::invalid_argument("FitDynamicBetaGamma: sizes");
  Eigen::MatrixXd A(n, 2);
  Eigen::VectorXd b(n);
  for (size_t k = 0; k < n; ++k) {
    double E, F;
    SplitEF(joint, alpha, le[k], E, F);
    A(k, 0) = (E + F) * (q[k] - theta_c);
    A(k, 1) = -(E + F) * qd[k];
    b[k] = tau_M[k] - (E - F);
  }
  const Eigen::Vector2d x = A.colPivHouseholderQr().solve(b);
  BetaGammaFit fit;
  fit.beta = x[0];
  fit.gamma = x[1];
  std::vector<double> pred(n);
  for (size_t k = 0; k < n; ++k)
    pred[k] = DynamicTorque(joint, alpha, fit.beta, fit.gamma, theta_c, le[k], q[k], qd[k]);
  fit.quality = Quality(tau_M, pred);
  return fit;
}

}  // namespace exotwin
