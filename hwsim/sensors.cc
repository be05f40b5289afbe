#include "hwsim/sensors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace exotwin::hwsim {

TorqueSensor::TorqueSensor(const TorqueSensorSpec& spec, uint64_t seed) : spec_(spec), rng_(seed) {}

double TorqueSensor::Read(double tau) {
  const double noise = rng_.Normal();  // drawn every sample so faults don't shift the random stream
  switch (fault_) {
    case SensorFault::kStuck: return last_;
    case SensorFault::kNaN: return std::numeric_limits<double>::quiet_NaN();
    default: break;
  }
  const double fs = spec_.range;
  const double x = std::clamp(tau / fs, -1.0, 1.0);
  // Non-linearity: a cubic bow x - x^3 scaled so its largest deviation (at x = 1/sqrt(3)) equals
  // nonlinearity_fs * FS: max(x - x^3) = 2/(3 sqrt 3).
  const double bow = spec_.nonlinearity_fs * fs * (x - x * x * x) / (2.0 / (3.0 * std::sqrt(3.0)));
  double v = (tau + spec_.offset) * (1.0 + spec_.gain) + bow + spec_.repeatability_fs * fs * noise;
  if (fault_ == SensorFault::kGlitch) v += 0.1 * fs;
  v = std::clamp(v, -fs, fs);
  v = std::round(v / spec_.resolution) * spec_.resolution;
  last_ = v;
  return v;
}

Encoder::Encoder(const EncoderSpec& spec) : spec_(spec) {}

double Encoder::resolution() const { return 2.0 * M_PI / std::ldexp(1.0, spec_.bits); }

double Encoder::Read(double q) {
  switch (fault_) {
    case SensorFault::kStuck: return last_;
    case SensorFault::kNaN: return std::numeric_limits<double>::quiet_NaN();
    case SensorFault::kGlitch: q += spec_.glitch; break;
    default: break;
  }
  const double res = resolution();
  last_ = std::round(q / res) * res;
  return last_;
}

SampleSkew::SampleSkew(int samples) : samples_(samples) {
  if (samples < 0) throw std::invalid_argument("SampleSkew: samples must be >= 0");
}

double SampleSkew::Push(double v) {
  if (samples_ == 0) return v;
  if (line_.empty())
    for (int i = 0; i < samples_; ++i) line_.push_back(v);
  line_.push_back(v);
  const double out = line_.front();
  line_.pop_front();
  return out;
}

MotorDriver::MotorDriver(const MotorDriverSpec& spec) : spec_(spec) {}

void MotorDriver::Command(double t, double torque, bool enable) {
  last_command_t_ = t;
  ever_commanded_ = true;
  tripped_ = false;
  enabled_ = enable && std::isfinite(torque);
  command_ = enabled_ ? std::clamp(torque, -spec_.limit, spec_.limit) : 0.0;
}

double MotorDriver::Update(double t, double dt) {
  if (ever_commanded_ && t - last_command_t_ > spec_.watchdog) {
    tripped_ = true;
    enabled_ = false;
    command_ = 0.0;
  }
  const double target = enabled_ ? command_ : 0.0;
  if (spec_.lag <= 0.0) applied_ = target;
  else applied_ += (target - applied_) * (1.0 - std::exp(-dt / spec_.lag));
  return applied_;
}

}  // namespace exotwin::hwsim
