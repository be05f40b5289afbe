// EXOwheel joint-module node (one per joint): encoder + torque sensor sampled at the module's rate and
// sent as JointStatus frames; JointCommand frames drive the motor driver (lag, saturation, watchdog).
// Faults are switches (ros2_control mock style). The node sees the plant only through Sample()'s
// arguments and Applied()'s result: the narrow plant interface of DESIGN.md.
#pragma once
#include <cstdint>

#include "hwsim/sensors.h"
#include "protocol/can_bus.h"
#include "protocol/messages.h"

namespace exotwin::hwsim {

struct JointModuleSpec {
  msg::Joint joint = msg::Joint::kHip;
  TorqueSensorSpec torque_sensor;
  EncoderSpec encoder;
  MotorDriverSpec driver;
  // Deliberate skew between the sensors, in module samples (SampleSkew, hwsim/sensors.h): 0 = encoder
  // and torque sensor sampled at one instant; k > 0 = the torque sensor samples k periods before the
  // encoder (the frame of t carries the torque of t - k T), k < 0 = the encoder is the older one.
  // Scenario key hardware.torque_sensor_skew.
  int torque_sensor_skew = 0;
};

// Switchable faults of a module.
struct JointModuleFaults {
  bool stale = false;          // stops sending status frames (module hung, cable cut)
  bool sensor_stuck = false;   // torque sensor and encoder repeat their last value, counter frozen
  bool encoder_glitch = false; // encoder reads off by EncoderSpec::glitch
  bool sensor_nan = false;     // torque sensor returns an invalid reading (flag set, value 0)
  bool drop_commands = false;  // command frames are ignored (receiver broken)
};

class JointModule {
 public:
  // bus: this node's endpoint (not owned, outlives the module).
  JointModule(const JointModuleSpec& spec, CanBus* bus, uint64_t seed);

  // Samples the sensors at the instant t (s), with the true link angle q(t) (rad) and the torque the
  // motor applies at t, tau_R(t) (N m; the sensor sits between motor and link, so it reads
  // tau_S = -tau_R, HJ15 eq. 8), and sends a JointStatus frame (unless stale). Returns the CanStatus of
  // the send. Both arguments must belong to the same instant (DESIGN.md "Sampling instant of a joint
  // node"): with the plant's semi-implicit Euler step, q(t) and the torque held over [t, t + dt]
  // (the driver's output at t, Applied()); the spec's torque_sensor_skew then delays one of them.
  CanStatus Sample(double t, double q, double tau_R);
  // Reads command frames (those addressed to this joint) and advances the driver to t by dt (s).
  // Returns the torque (N m) the motor applies during the next physics step.
  double Applied(double t, double dt);

  JointModuleFaults& faults() { return faults_; }
  const MotorDriver& driver() const { return driver_; }
  uint32_t commands_received() const { return commands_received_; }

 private:
  JointModuleSpec spec_;
  CanBus* bus_;
  TorqueSensor torque_sensor_;
  Encoder encoder_;
  SampleSkew torque_skew_, angle_skew_;  // delay lines of torque_sensor_skew (one of them is 0)
  MotorDriver driver_;
  JointModuleFaults faults_;
  uint8_t counter_ = 0;
  uint32_t commands_received_ = 0;
};

}  // namespace exotwin::hwsim
