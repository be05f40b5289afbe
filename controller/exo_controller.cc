#include "controller/exo_controller.h"

#include <cmath>
#include <limits>

#include "model/leg_dynamics.h"
#include "protocol/messages.h"

namespace exotwin::controller {

ExoController::ExoController(const ExoControllerConfig& cfg,
                             std::shared_ptr<const LegTrajectory> trajectory, CanBus* bus,
                             double t_start)
    : cfg_(cfg), trajectory_(std::move(trajectory)), bus_(bus), t_start_(t_start),
      est_{JointStateEstimator(cfg.estimator), JointStateEstimator(cfg.estimator)},
      pd_(cfg.hip, cfg.knee), safety_(cfg.safety) {
  tel_.tau_sensor[0] = tel_.tau_sensor[1] = std::numeric_limits<double>::quiet_NaN();
}

void ExoController::Tick(double t, const double* command) {
  tel_.t = t;
  new_sample_[0] = new_sample_[1] = false;
  CanFrame f;
  CanStatus st;
  while ((st = bus_->Receive(&f)) != CanStatus::kNoFrame) {
    if (st != CanStatus::kOk) continue;
    msg::EmgSamples e;
    if (msg::Decode(f, &e)) {
      for (int c = 0; c < msg::kEmgChannels; ++c) tel_.emg[c] = e.volts[c];
      ++tel_.emg_samples;
      continue;
    }
    msg::JointStatus s;
    if (!msg::Decode(f, &s)) continue;
    const int j = static_cast<int>(s.joint);
    ++tel_.frames_received;
    tel_.have_status[j] = true;
    counter_[j] = s.counter;
    const bool torque_ok = !(s.flags & msg::kStatusTorqueSensorFault);
    const bool angle_ok = !(s.flags & msg::kStatusEncoderFault);
    tel_.tau_sensor[j] = torque_ok ? s.torque : std::numeric_limits<double>::quiet_NaN();
    if (angle_ok) {
      rx_time_[j] = f.t;  // the age the supervisor sees is the angle's: an invalid angle is a lost one
      est_[j].Update(s.angle);
      new_sample_[j] = true;
    }
  }
  for (int j = 0; j < 2; ++j) {
    if (!new_sample_[j] && est_[j].initialised()) est_[j].Hold();
    tel_.est[j] = est_[j].estimate();
    tel_.age[j] = tel_.have_status[j] ? t - rx_time_[j] : std::numeric_limits<double>::infinity();
  }

  trajectory_->Sample(t - t_start_, &tel_.ref[0], &tel_.ref[1]);
  double ff[2] = {0, 0};
  if (cfg_.feedforward) {
    const Eigen::Vector2d tau = ActuatorTorque(cfg_.model, {tel_.ref[0].q, tel_.ref[1].q},
                                               {tel_.ref[0].qd, tel_.ref[1].qd},
                                               {tel_.ref[0].qdd, tel_.ref[1].qdd});
    ff[0] = tau[0];
    ff[1] = tau[1];
  }
  double cmd[2] = {0, 0};
  pd_.Update(tel_.ref[0], tel_.ref[1], tel_.est[0].q, tel_.est[0].qd, tel_.est[1].q, tel_.est[1].qd,
             ff[0], ff[1], &cmd[0], &cmd[1]);
  if (command) cmd[0] = command[0], cmd[1] = command[1];

  SafetyInput in;
  JointSafetyInput* js[2] = {&in.hip, &in.knee};
  for (int j = 0; j < 2; ++j) {
    js[j]->q = tel_.est[j].q;
    js[j]->qd = tel_.est[j].qd;
    js[j]->tau_sensor = tel_.tau_sensor[j];
    js[j]->tau_cmd = cmd[j];
    js[j]->age_s = tel_.age[j];
    js[j]->counter = counter_[j];
  }
  const bool started = tel_.have_status[0] && tel_.have_status[1];
  if (started) tel_.safety = safety_.Update(in);
  const double out[2] = {tel_.safety.tau_hip, tel_.safety.tau_knee};
  const bool enable = started && tel_.safety.state != SafetyState::kSafeTorqueOff;

  for (int j = 0; j < 2; ++j) {
    msg::JointCommand c;
    c.joint = static_cast<msg::Joint>(j);
    c.torque = enable ? out[j] : 0.0;
    c.enable = enable;
    c.counter = tx_counter_;
    tel_.tau_cmd[j] = c.torque;
    if (bus_->Send(msg::Encode(c)) == CanStatus::kOk) ++tel_.frames_sent;
    else ++tel_.send_failures;
  }
  // Heartbeat at 100 Hz, and at once when the latched faults change (keeps the bus below 60 % load;
  // the 1 kHz commands already feed the modules' watchdogs).
  const bool faults_changed = tel_.safety.fault_mask != last_fault_mask_;
  last_fault_mask_ = tel_.safety.fault_mask;
  const bool due = ticks_++ % kHeartbeatDivider == 0;
  if (!due && !faults_changed) {
    ++tx_counter_;
    return;
  }
  msg::ControllerHeartbeat hb;
  hb.state = static_cast<uint8_t>(tel_.safety.state);
  hb.fault_mask = static_cast<uint16_t>(tel_.safety.fault_mask);
  hb.first_fault = static_cast<uint8_t>(tel_.safety.first_fault);
  hb.counter = tx_counter_;
  if (bus_->Send(msg::Encode(hb)) == CanStatus::kOk) ++tel_.frames_sent;
  else ++tel_.send_failures;
  ++tx_counter_;
}

}  // namespace exotwin::controller
