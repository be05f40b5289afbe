// HAL-3 knee unit node (Hayashi et al. sec. I and Fig. 6): the potentiometer at the knee joint and the
// strain gauge on the frame between the actuator and the lower-leg cuff, sampled at 1 kHz and sent as
// HalKneeStatus frames (0x190); HalKneeCommand frames (0x110) drive the motor driver.
// The node sees the plant only through Sample()'s plain numbers and Applied()'s result.
// HAL's convention: angle 0 = lower leg hanging, + extension; strain torque + = HAL pushes the leg
// into extension (Hayashi Fig. 7-C).
#pragma once
#include <cstdint>

#include "core/rng.h"
#include "hwsim/sensors.h"
#include "protocol/can_bus.h"
#include "protocol/messages.h"

namespace exotwin::hwsim {

// Potentiometer: a 14-bit ADC over 300 deg (our choice; the papers only say "potentiometer").
struct PotentiometerSpec {
  double range = 5.236;     // rad of electrical travel (300 deg)
  int adc_bits = 14;        // resolution = range / 2^bits (3.2e-4 rad)
  double noise = 2e-4;      // rad, 1-sigma wiper + ADC noise
  double offset = 0.0;      // rad, mounting offset
};

// Strain gauge bridge calibrated in N m (our choice: +-60 N m, 0.01 N m resolution = the frame's LSB).
struct StrainGaugeSpec {
  double range = 60.0;      // N m
  double resolution = 0.01; // N m
  double noise = 0.05;      // N m, 1-sigma
  double gain_error = 0.0;  // relative (0.02 = reads 2 % high)
  double offset = 0.0;      // N m
};

struct Hal3KneeNodeSpec {
  PotentiometerSpec pot;
  StrainGaugeSpec strain;
  MotorDriverSpec driver{0.5e-3, 60.0, 0.02};  // limit = models/hal3_knee.xml ctrlrange
  // Deliberate skew, in node samples, of the strain gauge against the potentiometer (as
  // JointModuleSpec::torque_sensor_skew; SampleSkew, hwsim/sensors.h): 0 = one sampling instant.
  int torque_sensor_skew = 0;
};

class Hal3KneeNode {
 public:
  // bus: this node's endpoint (not owned, outlives the node); seed drives both sensors' noise.
  Hal3KneeNode(const Hal3KneeNodeSpec& spec, CanBus* bus, uint64_t seed);
  // Samples at the instant t (s) the true knee angle th(t) (rad) and the true frame torque
  // tau_int(t) (N m) and sends one HalKneeStatus frame. Returns the CanStatus of the send. Both
  // arguments belong to the same instant (DESIGN.md "Sampling instant of a joint node"): th(t) and the
  // frame torque of the plant step [t, t + dt] (Hal3Plant::interaction_torque, computed from the state
  // at t); the spec's torque_sensor_skew then delays one of them.
  CanStatus Sample(double t, double th, double tau_int);
  // Reads HalKneeCommand frames and advances the driver to t by dt (s); returns the motor torque
  // (N m) for the next physics step.
  double Applied(double t, double dt);
  double last_angle() const { return angle_; }    // rad, as sent
  double last_strain() const { return strain_; }  // N m, as sent
  uint32_t commands_received() const { return commands_received_; }
  const MotorDriver& driver() const { return driver_; }

  double ReadPotentiometer(double th);   // rad, quantized and noisy
  double ReadStrainGauge(double tau);    // N m, quantized, noisy, saturated

 private:
  Hal3KneeNodeSpec spec_;
  CanBus* bus_;
  NormalRng<NormalBoxMullerPair<BoxMullerU1::kNonzeroUniform>> rng_;  // sensor noise
  MotorDriver driver_;
  SampleSkew strain_skew_, angle_skew_;  // delay lines of torque_sensor_skew (one of them is 0)
  double angle_ = 0, strain_ = 0;
  uint8_t counter_ = 0;
  uint32_t commands_received_ = 0;
};

}  // namespace exotwin::hwsim
