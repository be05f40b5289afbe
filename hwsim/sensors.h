// Physical models of the joint-module sensors: every imperfection a parameter, every fault a switch.
// Pure device physics (no bus): the joint-module node packs their readings into frames.
#pragma once
#include <cstdint>

#include "core/ring_queue.h"
#include "core/rng.h"

namespace exotwin::hwsim {

// Faults a sensor can be switched into (mock-style switches; kNone = healthy).
enum class SensorFault { kNone, kStuck, kNaN, kGlitch };

// EXOwheel joint torque sensor (Hwang & Jeon sec. 2): range +-120 N m, resolution 0.015 N m,
// non-linearity 0.03 % FS, repeatability 0.02 % FS; plus offset and saturation.
struct TorqueSensorSpec {
  double range = 120.0;             // N m, full scale (saturates beyond)
  double resolution = 0.015;        // N m per LSB
  double nonlinearity_fs = 0.0003;  // max deviation from linear as a fraction of FS (a cubic bow)
  double repeatability_fs = 0.0002; // 1-sigma random error as a fraction of FS
  double offset = 0.0;              // N m
  double gain = 0.0;                // relative: the reading (tau + offset) * (1 + gain) before the bow and noise
};

class TorqueSensor {
 public:
  TorqueSensor(const TorqueSensorSpec& spec, uint64_t seed);
  // Reading (N m) of a true torque tau (N m): (tau + offset) (1 + gain) + non-linearity + noise, saturation at the
  // range, quantization to the resolution. NaN when the kNaN fault is on; the last reading when stuck.
  double Read(double tau);
  void SetFault(SensorFault f) { fault_ = f; }
  SensorFault fault() const { return fault_; }
  const TorqueSensorSpec& spec() const { return spec_; }

 private:
  TorqueSensorSpec spec_;
  NormalRng<NormalBoxMullerPair<BoxMullerU1::kNonzeroUniform>> rng_;  // sensor noise
  SensorFault fault_ = SensorFault::kNone;
  double last_ = 0.0;
};

// Absolute joint encoder with 2^bits counts per revolution.
struct EncoderSpec {
  int bits = 19;
  double glitch = 0.2;  // rad, size of the jump of the kGlitch fault
};

class Encoder {
 public:
  explicit Encoder(const EncoderSpec& spec);
  // Reading (rad) of a true angle q (rad): quantized to the count; stuck, NaN or glitched on faults.
  double Read(double q);
  double resolution() const;
  void SetFault(SensorFault f) { fault_ = f; }

 private:
  EncoderSpec spec_;
  SensorFault fault_ = SensorFault::kNone;
  double last_ = 0.0;
};

// Sampling skew between the two sensors of a node (JointModuleSpec / Hal3KneeNodeSpec
// ::torque_sensor_skew, DESIGN.md "Sampling instant of a joint node"). A node samples its angle sensor
// and its torque sensor at one instant t_k (skew 0, the default). A skew of k samples (k > 0) makes the
// torque sensor sample k node periods before the angle sensor: the frame of t_k carries q(t_k) beside
// the torque of t_{k-k}; k < 0 makes the angle sensor the older one by |k| samples. This class is the
// delay line of the older sensor's true input.
class SampleSkew {
 public:
  // samples >= 0 (the delay of this input); throws std::invalid_argument otherwise.
  explicit SampleSkew(int samples);
  // The true value at this sample in, the value of `samples` samples ago out (the first value until
  // the line is full: the sensor held its first sample before the record started).
  double Push(double v);
  int samples() const { return samples_; }

 private:
  int samples_;
  RingQueue<double> line_;
};

// Motor driver: torque command -> applied torque through a first-order current-loop lag, saturation
// and a watchdog that cuts the torque when commands stop arriving.
struct MotorDriverSpec {
  double lag = 0.5e-3;       // s, current-loop time constant (0 = ideal)
  double limit = 120.0;      // N m saturation
  double watchdog = 0.02;    // s without a command before torque is cut
};

class MotorDriver {
 public:
  explicit MotorDriver(const MotorDriverSpec& spec);
  // A command (N m) arrived at time t (s); enable = false commands zero torque.
  void Command(double t, double torque, bool enable);
  // Advances the current loop to time t (s) by dt (s) and returns the applied torque (N m).
  double Update(double t, double dt);
  bool watchdog_tripped() const { return tripped_; }
  double applied() const { return applied_; }

 private:
  MotorDriverSpec spec_;
  double command_ = 0.0, applied_ = 0.0, last_command_t_ = 0.0;
  bool enabled_ = false, tripped_ = false, ever_commanded_ = false;
};

}  // namespace exotwin::hwsim
