// Safety supervisor: pure logic, called once per control tick with the latest measurements, their
// ages and frame counters, and the torque the controller wants to apply. It latches faults and
// returns the torque that may actually be applied.
//
// States (stable integer values): kRunning -> kSafeDamping -> kSafeTorqueOff, only upwards until
// Reset(). In kSafeDamping every joint gets tau = clamp(-D qd, +-tau_damp_max) (0 if qd is not
// finite); in kSafeTorqueOff tau = 0. Faults that leave the velocity trustworthy (limits, overspeed,
// torque, bad command) lead to damping; faults that make it untrustworthy (stale or stuck frames,
// non-finite measurements or ages) and the emergency stop lead to torque off.
//
// Reaction time: a condition present in the inputs of a tick is detected in that same Update() call
// and the returned torque is already the safe one, i.e. at most one tick (1 ms at 1 kHz) after the
// condition becomes true in the measurements. The output torque is never NaN or inf.
// Real-time path (Update) is allocation- and exception-free.
#pragma once
#include <cstdint>

namespace exotwin::controller {

enum class SafetyState : int { kRunning = 0, kSafeDamping = 1, kSafeTorqueOff = 2 };

// Fault kinds; stable integer values (bus / logs). Latched as bit (1u << value) in the fault mask.
enum class FaultCode : int {
  kNone = 0,
  kJointLimit = 1,        // q outside [q_min + margin, q_max - margin]           -> damping
  kOverspeed = 2,         // |qd| > qd_max                                         -> damping
  kSensorTorqueLimit = 3, // |tau_sensor| > tau_sensor_max                         -> damping
  kCommandTorqueLimit = 4,// |tau_cmd| > tau_cmd_max                               -> damping
  kNonFiniteCommand = 5,  // tau_cmd or tau_sensor NaN/inf                         -> damping
  kNonFiniteMeasurement = 6, // q, qd, age NaN/inf, or age < 0                     -> torque off
  kStaleFrame = 7,        // age > max_age_s                                       -> torque off
  kStuckCounter = 8,      // counter unchanged on more than max_counter_repeats ticks -> torque off
  kEmergencyStop = 9,     // external stop request                                 -> torque off
};

// Which joint raised a fault (bit mask in SafetyOutput::joint_mask).
enum JointBit : uint32_t { kHipBit = 1u, kKneeBit = 2u };

struct JointSafetyLimits {
  double q_min = 0, q_max = 0;  // rad, mechanical range of the joint
  double q_margin = 0;          // rad, >= 0: trip this far inside the mechanical range
  double qd_max = 0;            // rad/s
  double tau_sensor_max = 0;    // N m, |torque sensor reading| limit
  double tau_cmd_max = 0;       // N m, |commanded torque| limit
  double damping = 0;           // N m s/rad, D of the safe damping torque, >= 0
  double tau_damp_max = 0;      // N m, clamp of the damping torque, >= 0
};

struct SafetyConfig {
  JointSafetyLimits hip, knee;
  double max_age_s = 0.003;     // s: a frame older than this is stale (3 ticks at 1 kHz)
  int max_counter_repeats = 2;  // ticks on which an unchanged counter is tolerated (0 = none)
  // A default for the EXOwheel-like rig: hip -30..120 deg, knee -120..5 deg, margin 3 deg,
  // qd_max 300 deg/s, sensor 60 N m, command 40 N m, D = 2 N m s/rad clamped at 20 N m.
  static SafetyConfig Default();
};

// Latest values of one joint as seen by the controller this tick.
struct JointSafetyInput {
  double q = 0;           // rad, latest encoder angle
  double qd = 0;          // rad/s, estimated velocity
  double tau_sensor = 0;  // N m, latest torque-sensor reading
  double tau_cmd = 0;     // N m, torque the controller wants to apply this tick
  double age_s = 0;       // s, time since the frame carrying q / tau_sensor was received
  uint32_t counter = 0;   // that frame's counter (any width; only changes matter)
};

struct SafetyInput {
  JointSafetyInput hip, knee;
  bool emergency_stop = false;
};

struct SafetyOutput {
  SafetyState state = SafetyState::kRunning;
  uint32_t fault_mask = 0;  // latched faults, bit (1u << FaultCode)
  uint32_t joint_mask = 0;  // latched joints that raised a fault (JointBit)
  FaultCode first_fault = FaultCode::kNone;  // first latched fault since Reset()
  double tau_hip = 0, tau_knee = 0;  // N m to apply: tau_cmd when running, else the safe torque
};

class SafetySupervisor {
 public:
  // Limits consistent (q_min + margin < q_max - margin, positive limits, finite); throws InputError.
  explicit SafetySupervisor(const SafetyConfig& cfg);
  // One tick. Returns the state after this tick's checks and the torque to apply.
  SafetyOutput Update(const SafetyInput& in);
  // Clears latched faults and returns to kRunning (a persisting condition trips again next tick).
  void Reset();
  const SafetyOutput& last() const { return out_; }
  // Safe state a fault leads to.
  static SafetyState Severity(FaultCode f);

 private:
  struct CounterTrack {
    bool seen = false;
    uint32_t last = 0;
    int repeats = 0;
  };
  void CheckJoint(const JointSafetyLimits& lim, const JointSafetyInput& j, uint32_t bit,
                  CounterTrack* track);
  void Raise(FaultCode f, uint32_t joint_bit);
  SafetyConfig cfg_;
  SafetyOutput out_;
  CounterTrack hip_track_, knee_track_;
};

}  // namespace exotwin::controller
