#include "identification/one_joint_identification.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "core/error.h"
#include "dsp/statistics.h"
#include "model/one_joint.h"

namespace exotwin {

OneJointEstimate IdentifyOneJoint(const std::vector<MeasuredData>& records, double cutoff_hz, double trim_s,
                                  bool friction) {
  if (records.empty()) throw InputError("identify: expected at least one one-joint record");
  OneJointEstimate e;
  e.names = {"I", "mgl"};
  if (friction) e.names.insert(e.names.end(), {"R", "C"});
  const int p = static_cast<int>(e.names.size());
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> y;
  for (const MeasuredData& d : records) {
    if (!d.one_joint)
      throw InputError(d.source + ": a record with hip columns among one-joint records, expected t, q_knee, tau_knee "
                                  "(no hip column) in every file");
    if (d.size() < 200)
      throw InputError(d.source + ": " + std::to_string(d.size()) + " samples, expected at least 200");
    const Kinematics k = DeriveKinematics(d, cutoff_hz);
    for (size_t i = 0; i < k.t.size(); ++i) {
      if (k.t[i] < k.t.front() + trim_s || k.t[i] > k.t.back() - trim_s) continue;
      Eigen::VectorXd r(p);
      const double qd = k.qd[1][i];
      r[0] = k.qdd[1][i];
      r[1] = std::sin(k.q[1][i]);
      if (friction) r[2] = qd, r[3] = qd > 0 ? 1.0 : (qd < 0 ? -1.0 : 0.0);
      rows.push_back(r);
      y.push_back(-d.tau_knee()[i]);  // tau_R = -tau_S (HJ15 eq. 8)
    }
  }
  const size_t n = rows.size();
  if (n < static_cast<size_t>(10 * p)) throw InputError(records[0].source + ": too few samples after the trim");
  Eigen::MatrixXd X(n, p);
  Eigen::VectorXd Y(n);
  for (size_t i = 0; i < n; ++i) X.row(static_cast<Eigen::Index>(i)) = rows[i].transpose(), Y[i] = y[i];
  const Eigen::VectorXd s = X.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd Xn = X * s.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Xn, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  e.condition = sv[0] / std::max(sv[p - 1], 1e-300);
  if (!(e.condition < 1e6))
    throw InputError(records[0].source + ": the regressor of " + std::string(friction ? "I, mgl, R, C" : "I, mgl") +
                     " has no rank (condition " + std::to_string(e.condition) +
                     "), expected a record where the joint swings (accelerates and moves through angles)");
  const Eigen::VectorXd theta = s.asDiagonal() * svd.solve(Y);
  const Eigen::VectorXd res = Y - X * theta;
  e.rmse = std::sqrt(res.squaredNorm() / static_cast<double>(n));
  e.autocorrelation_rows = std::max(1.0, AutocorrelationLength(res.data(), n));
  const double n_eff = static_cast<double>(n) / e.autocorrelation_rows;
  const double s2 = res.squaredNorm() / std::max(1.0, static_cast<double>(n) - p) * static_cast<double>(n) / n_eff;
  const Eigen::MatrixXd cov = s2 * (X.transpose() * X).inverse();
  e.samples = n;
  for (int k = 0; k < p; ++k) e.value.push_back(theta[k]), e.se.push_back(std::sqrt(cov(k, k)));
  return e;
}

LegParams OneJointParamsOf(const OneJointEstimate& e) {
  OneJointModel m;
  m.device.I = e.value[0];
  m.device.mgl = e.value[1];
  if (e.value.size() == 4) m.R = std::max(0.0, e.value[2]), m.C = std::max(0.0, e.value[3]);
  return EmbedOneJointModel(m, 9.81, {});
}

std::string OneJointIdentificationYaml(const OneJointEstimate& e, double cutoff_hz) {
  std::ostringstream os;
  os.precision(6);
  os << "identification:\n  method: least squares of I thdd + mgl sin th" << (e.value.size() == 4 ? " + R thd + C sgn(thd)" : "")
     << " (HKS05 eq. 4), derivatives at " << cutoff_hz << " Hz\n  samples: " << e.samples
     << "\n  residual_rmse: " << e.rmse << "\n  condition_number: " << e.condition
     << "\n  autocorrelation_rows: " << e.autocorrelation_rows << "\n  standard_errors: {";
  for (size_t k = 0; k < e.names.size(); ++k) os << (k ? ", " : "") << e.names[k] << ": " << e.se[k];
  os << "}\n";
  return os.str();
}

}  // namespace exotwin
