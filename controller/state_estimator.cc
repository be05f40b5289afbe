#include "controller/state_estimator.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace exotwin::controller {
namespace {

using cd = std::complex<double>;

cd Cascade(const std::vector<dsp::Biquad>& sos, cd z) {
  cd h = 1.0;
  const cd zi = 1.0 / z;
  for (const dsp::Biquad& s : sos)
    h *= (s.b0 + s.b1 * zi + s.b2 * zi * zi) / (1.0 + s.a1 * zi + s.a2 * zi * zi);
  return h;
}

std::vector<dsp::Biquad> Design(int order, double fs, double fc, const char* name) {
  try {
    return dsp::DesignButterworth(order, dsp::BandType::kLowPass, fs, fc);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("EstimatorConfig: ") + name + ": " + e.what());
  }
}

}  // namespace

JointStateEstimator::JointStateEstimator(const EstimatorConfig& cfg) : cfg_(cfg) {
  if (!(std::isfinite(cfg.sample_rate_hz) && cfg.sample_rate_hz > 0))
    throw InputError("EstimatorConfig: sample_rate_hz must be > 0");
  if (cfg.order < 1 || cfg.order > 8) throw InputError("EstimatorConfig: order must be in 1..8");
  dt_ = 1.0 / cfg.sample_rate_hz;
  sos_v_ = Design(cfg.order, cfg.sample_rate_hz, cfg.velocity_cutoff_hz, "velocity_cutoff_hz");
  sos_a_ = Design(cfg.order, cfg.sample_rate_hz, cfg.acceleration_cutoff_hz, "acceleration_cutoff_hz");
  lp_v_ = dsp::SosFilter(sos_v_);
  lp_a_ = dsp::SosFilter(sos_a_);
}

void JointStateEstimator::Reset() {
  initialised_ = false;
  est_ = JointSetpoint{};
  q_prev_ = qd_prev_ = 0;
}

void JointStateEstimator::Advance(double q) {
  const double qd = lp_v_.Step((q - q_prev_) / dt_);
  const double qdd = lp_a_.Step((qd - qd_prev_) / dt_);
  q_prev_ = q;
  qd_prev_ = qd;
  est_ = {q, qd, qdd};
}

EstimatorStatus JointStateEstimator::Update(double q) {
  if (!std::isfinite(q)) {
    Hold();
    return EstimatorStatus::kNonFinite;
  }
  if (!initialised_) {
    lp_v_.ResetSteady(0.0);
    lp_a_.ResetSteady(0.0);
    q_prev_ = q;
    qd_prev_ = 0;
    est_ = {q, 0.0, 0.0};
    initialised_ = true;
    return EstimatorStatus::kOk;
  }
  Advance(q);
  return EstimatorStatus::kOk;
}

void JointStateEstimator::Hold() {
  if (!initialised_) return;
  Advance(q_prev_ + est_.qd * dt_);
}

std::complex<double> JointStateEstimator::VelocityResponse(double f_hz) const {
  const double w = 2.0 * M_PI * f_hz;
  const cd z = std::polar(1.0, w * dt_);
  const cd diff = (1.0 - 1.0 / z) / dt_;  // backward difference
  return diff * Cascade(sos_v_, z) / cd(0.0, w);
}

std::complex<double> JointStateEstimator::AccelerationResponse(double f_hz) const {
  const double w = 2.0 * M_PI * f_hz;
  const cd z = std::polar(1.0, w * dt_);
  const cd diff = (1.0 - 1.0 / z) / dt_;
  return diff * diff * Cascade(sos_v_, z) * Cascade(sos_a_, z) / cd(-w * w, 0.0);
}

double JointStateEstimator::VelocityDelay(double f_hz) const {
  return -std::arg(VelocityResponse(f_hz)) / (2.0 * M_PI * f_hz);
}

double JointStateEstimator::AccelerationDelay(double f_hz) const {
  return -std::arg(AccelerationResponse(f_hz)) / (2.0 * M_PI * f_hz);
}

}  // namespace exotwin::controller
