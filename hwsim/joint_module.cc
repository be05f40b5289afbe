#include "hwsim/joint_module.h"

#include <algorithm>
#include <cmath>

namespace exotwin::hwsim {

JointModule::JointModule(const JointModuleSpec& spec, CanBus* bus, uint64_t seed)
    : spec_(spec), bus_(bus), torque_sensor_(spec.torque_sensor, seed), encoder_(spec.encoder),
      torque_skew_(std::max(spec.torque_sensor_skew, 0)), angle_skew_(std::max(-spec.torque_sensor_skew, 0)),
      driver_(spec.driver) {}

CanStatus JointModule::Sample(double t, double q, double tau_R) {
  torque_sensor_.SetFault(faults_.sensor_stuck ? SensorFault::kStuck
                                               : (faults_.sensor_nan ? SensorFault::kNaN : SensorFault::kNone));
  encoder_.SetFault(faults_.sensor_stuck ? SensorFault::kStuck
                                         : (faults_.encoder_glitch ? SensorFault::kGlitch : SensorFault::kNone));
  const double tau_S = torque_sensor_.Read(-torque_skew_.Push(tau_R));
  const double angle = encoder_.Read(angle_skew_.Push(q));
  if (faults_.stale) return CanStatus::kOk;  // nothing leaves the module
  msg::JointStatus s;
  s.joint = spec_.joint;
  s.angle = angle;
  s.torque = std::isfinite(tau_S) ? tau_S : 0.0;
  s.flags = 0;
  if (!std::isfinite(tau_S)) s.flags |= msg::kStatusTorqueSensorFault;
  if (!std::isfinite(angle)) s.flags |= msg::kStatusEncoderFault;
  if (driver_.watchdog_tripped()) s.flags |= msg::kStatusWatchdog;
  else if (std::abs(driver_.applied()) > 0.0 || commands_received_ > 0) s.flags |= msg::kStatusEnabled;
  if (!faults_.sensor_stuck) ++counter_;  // a stuck module repeats its whole frame, counter included
  s.counter = counter_;
  (void)t;
  return bus_->Send(msg::Encode(s));
}

double JointModule::Applied(double t, double dt) {
  CanFrame f;
  CanStatus st;
  while ((st = bus_->Receive(&f)) != CanStatus::kNoFrame) {
    if (st != CanStatus::kOk) continue;  // error frames: nothing to act on
    msg::JointCommand c;
    if (!msg::Decode(f, &c) || c.joint != spec_.joint) continue;
    if (faults_.drop_commands) continue;
    ++commands_received_;
    driver_.Command(f.t, c.torque, c.enable);
  }
  return driver_.Update(t, dt);
}

}  // namespace exotwin::hwsim
