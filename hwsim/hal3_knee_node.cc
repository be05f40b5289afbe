// HAL-3 knee unit node: see hal3_knee_node.h.
#include "hwsim/hal3_knee_node.h"

#include <algorithm>
#include <cmath>

namespace exotwin::hwsim {

Hal3KneeNode::Hal3KneeNode(const Hal3KneeNodeSpec& spec, CanBus* bus, uint64_t seed)
    : spec_(spec), bus_(bus), rng_(seed), driver_(spec.driver),
      strain_skew_(std::max(spec.torque_sensor_skew, 0)), angle_skew_(std::max(-spec.torque_sensor_skew, 0)) {}

double Hal3KneeNode::ReadPotentiometer(double th) {
  const double lsb = spec_.pot.range / std::ldexp(1.0, spec_.pot.adc_bits);
  const double half = 0.5 * spec_.pot.range;
  const double v = std::clamp(th + spec_.pot.offset + spec_.pot.noise * rng_.Normal(), -half, half);
  return std::round(v / lsb) * lsb;
}

double Hal3KneeNode::ReadStrainGauge(double tau) {
  const StrainGaugeSpec& s = spec_.strain;
  const double v = std::clamp(tau * (1 + s.gain_error) + s.offset + s.noise * rng_.Normal(), -s.range, s.range);
  return std::round(v / s.resolution) * s.resolution;
}

CanStatus Hal3KneeNode::Sample(double, double th, double tau_int) {
  angle_ = ReadPotentiometer(angle_skew_.Push(th));
  strain_ = ReadStrainGauge(strain_skew_.Push(tau_int));
  msg::HalKneeStatus s;
  s.angle = angle_;
  s.torque = strain_;
  s.flags = 0;
  if (driver_.watchdog_tripped()) s.flags |= msg::kStatusWatchdog;
  else if (commands_received_ > 0) s.flags |= msg::kStatusEnabled;
  if (std::abs(driver_.applied()) >= spec_.driver.limit) s.flags |= msg::kStatusTorqueLimit;
  s.counter = ++counter_;
  return bus_->Send(msg::Encode(s));
}

double Hal3KneeNode::Applied(double t, double dt) {
  CanFrame f;
  CanStatus st;
  while ((st = bus_->Receive(&f)) != CanStatus::kNoFrame) {
    if (st != CanStatus::kOk) continue;
    msg::HalKneeCommand c;
    if (!msg::Decode(f, &c)) continue;
    ++commands_received_;
    driver_.Command(f.t, c.torque, c.enable);
  }
  return driver_.Update(t, dt);
}

}  // namespace exotwin::hwsim
