// The EXOwheel control loop: what runs at 1 kHz on the exoskeleton's computer. It talks to the joint
// modules only through a CanBus (the virtual bus in the twin, SocketCAN on the rig): reads their
// JointStatus frames, estimates velocities causally, tracks a reference with PD + model feed-forward,
// lets the safety supervisor veto, and sends JointCommand frames and its heartbeat (state + faults).
// Real-time path (Tick) allocates nothing and throws nothing; set-up throws InputError.
#pragma once
#include <memory>

#include "controller/pd_controller.h"
#include "controller/safety_supervisor.h"
#include "controller/state_estimator.h"
#include "controller/trajectory.h"
#include "model/lumped_params.h"
#include "protocol/can_bus.h"

namespace exotwin::controller {

struct ExoControllerConfig {
  double rate_hz = 1000.0;  // Hz, Tick() rate
  PdGains hip{600, 30, 100}, knee{400, 15, 100};
  bool feedforward = true;  // add M qdd + V + G + P of `model` at the reference
  LegParams model;          // the controller's own model of exo (+ subject) for the feed-forward
  EstimatorConfig estimator;
  SafetyConfig safety = SafetyConfig::Default();
};

// What one tick saw and did (for logging; the rig would stream it over its telemetry link).
struct ControllerTelemetry {
  double t = 0;
  JointSetpoint ref[2];      // reference (hip, knee)
  JointSetpoint est[2];      // estimated state
  double tau_sensor[2] = {0, 0};  // latest torque-sensor readings tau_S, N m (NaN if invalid)
  double tau_cmd[2] = {0, 0};     // torque sent to the modules, N m
  double age[2] = {0, 0};         // s since the latest status frame with a valid angle, per joint
  SafetyOutput safety;
  double emg[5] = {0, 0, 0, 0, 0};  // latest EMG sample after the amplifier, V (GMAX, VM, RF, ST, GAS)
  uint32_t emg_samples = 0;          // EMG frames received
  uint32_t frames_received = 0, frames_sent = 0, send_failures = 0;
  bool have_status[2] = {false, false};
};

class ExoController {
 public:
  // trajectory: the reference, sampled at t - t_start; bus: this node's endpoint (not owned).
  ExoController(const ExoControllerConfig& cfg, std::shared_ptr<const LegTrajectory> trajectory,
                CanBus* bus, double t_start = 0.0);
  // One control period at time t (s): read frames, estimate, control, supervise, send. `command`
  // (N m, hip then knee; may be null): the control law's output given from outside (a controller
  // written in Python stepping the twin, python/) in place of PD + feed-forward; the reference is still
  // sampled (telemetry) and the safety supervisor still vetoes and limits it.
  void Tick(double t, const double* command = nullptr);
  const ControllerTelemetry& telemetry() const { return tel_; }
  SafetyState state() const { return tel_.safety.state; }

 private:
  ExoControllerConfig cfg_;
  std::shared_ptr<const LegTrajectory> trajectory_;
  CanBus* bus_;
  double t_start_;
  JointStateEstimator est_[2];
  LegPdController pd_;
  SafetySupervisor safety_;
  ControllerTelemetry tel_;
  double rx_time_[2] = {0, 0};
  uint32_t counter_[2] = {0, 0};
  bool new_sample_[2] = {false, false};
  uint8_t tx_counter_ = 0;
  uint32_t last_fault_mask_ = 0;
  uint32_t ticks_ = 0;
  static constexpr int kHeartbeatDivider = 10;  // 1 kHz / 10 = 100 Hz
};

}  // namespace exotwin::controller
