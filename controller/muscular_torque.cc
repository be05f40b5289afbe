// Muscular torque estimate, eq. (9)-(10) of Hwang & Jeon 2015: see muscular_torque.h.
#include "controller/muscular_torque.h"

#include <stdexcept>

#include "model/leg_dynamics.h"

namespace exotwin {

Eigen::Vector2d PassiveTorqueEstimate(const LegParams& identified, const Eigen::Vector2d& q,
                                      const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  return -ActuatorTorque(identified, q, qd, qdd);  // eq. (10): -(M qdd + V + G + P)
}

Eigen::Vector2d MuscularTorque(const LegParams& identified, const Eigen::Vector2d& q,
                               const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                               const Eigen::Vector2d& tau_S) {
  return tau_S - PassiveTorqueEstimate(identified, q, qd, qdd);  // eq. (9)
}

std::vector<Eigen::Vector2d> MuscularTorqueOffline(const LegParams& identified,
                                                   const std::vector<Eigen::Vector2d>& q,
                                                   const std::vector<Eigen::Vector2d>& tau_S,
                                                   double dt, double fc) {
  if (q.size() != tau_S.size() || q.size() < 8 || !(dt > 0))
    throw std::invalid_argument("MuscularTorqueOffline: q, tau_S same length >= 8, dt > 0");
  const auto sos = dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / dt, fc);
  std::vector<double> qf[2], qd[2], qdd[2];
  for (int j = 0; j < 2; ++j) {
    std::vector<double> x(q.size());
    for (size_t k = 0; k < q.size(); ++k) x[k] = q[k][j];
    qf[j] = dsp::FiltFilt(sos, x);
    qd[j] = dsp::Gradient(qf[j], dt);
    qdd[j] = dsp::Gradient(qd[j], dt);
  }
  std::vector<Eigen::Vector2d> out(q.size());
  for (size_t k = 0; k < q.size(); ++k)
    out[k] = MuscularTorque(identified, q[k], {qd[0][k], qd[1][k]}, {qdd[0][k], qdd[1][k]}, tau_S[k]);
  return out;
}

MuscularTorqueEstimator::MuscularTorqueEstimator(const LegParams& identified, double dt, double fc)
    : params_(identified), dt_(dt) {
  if (!(dt > 0)) throw std::invalid_argument("MuscularTorqueEstimator: dt must be > 0");
  const auto sos = dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / dt, fc);
  f_[0] = dsp::SosFilter(sos);
  f_[1] = dsp::SosFilter(sos);
}

Eigen::Vector2d MuscularTorqueEstimator::Step(const Eigen::Vector2d& q, const Eigen::Vector2d& tau_S) {
  Eigen::Vector2d qf;
  for (int j = 0; j < 2; ++j) {
    if (n_ == 0) f_[j].ResetSteady(q[j]);
    qf[j] = f_[j].Step(q[j]);
  }
  if (n_ == 0) q1_ = q2_ = qf;
  const Eigen::Vector2d qd = (qf - q1_) / dt_;
  const Eigen::Vector2d qdd = (qf - 2 * q1_ + q2_) / (dt_ * dt_);
  q2_ = q1_;
  q1_ = qf;
  ++n_;
  return MuscularTorque(params_, qf, qd, qdd, tau_S);
}

}  // namespace exotwin
