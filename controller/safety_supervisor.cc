#include "controller/safety_supervisor.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/units.h"

namespace exotwin::controller {
namespace {


void Validate(const JointSafetyLimits& l, const std::string& name) {
  auto bad = [&](const std::string& what) { throw InputError("SafetyConfig." + name + ": " + what); };
  const double v[] = {l.q_min, l.q_max, l.q_margin, l.qd_max, l.tau_sensor_max, l.tau_cmd_max,
                      l.damping, l.tau_damp_max};
  for (double x : v)
    if (!std::isfinite(x)) bad("all limits must be finite");
  if (l.q_margin < 0) bad("q_margin must be >= 0 rad");
  if (!(l.q_min + l.q_margin < l.q_max - l.q_margin)) bad("need q_min + q_margin < q_max - q_margin");
  if (!(l.qd_max > 0)) bad("qd_max must be > 0 rad/s");
  if (!(l.tau_sensor_max > 0)) bad("tau_sensor_max must be > 0 N m");
  if (!(l.tau_cmd_max > 0)) bad("tau_cmd_max must be > 0 N m");
  if (l.damping < 0) bad("damping must be >= 0 N m s/rad");
  if (l.tau_damp_max < 0) bad("tau_damp_max must be >= 0 N m");
}

double DampingTorque(const JointSafetyLimits& l, double qd) {
  if (!std::isfinite(qd)) return 0.0;
  const double t = -l.damping * qd;
  if (!std::isfinite(t)) return 0.0;
  return std::clamp(t, -l.tau_damp_max, l.tau_damp_max);
}

}  // namespace

SafetyConfig SafetyConfig::Default() {
  SafetyConfig c;
  JointSafetyLimits j;
  j.q_margin = 3 * kRadPerDeg;
  j.qd_max = 300 * kRadPerDeg;
  j.tau_sensor_max = 60;
  j.tau_cmd_max = 40;
  j.damping = 2;
  j.tau_damp_max = 20;
  c.hip = j;
  c.hip.q_min = -30 * kRadPerDeg;
  c.hip.q_max = 120 * kRadPerDeg;
  c.knee = j;
  c.knee.q_min = -120 * kRadPerDeg;
  c.knee.q_max = 5 * kRadPerDeg;
  return c;
}

SafetySupervisor::SafetySupervisor(const SafetyConfig& cfg) : cfg_(cfg) {
  Validate(cfg.hip, "hip");
  Validate(cfg.knee, "knee");
  if (!(std::isfinite(cfg.max_age_s) && cfg.max_age_s > 0))
    throw InputError("SafetyConfig: max_age_s must be > 0 s");
  if (cfg.max_counter_repeats < 0) throw InputError("SafetyConfig: max_counter_repeats must be >= 0");
}

SafetyState SafetySupervisor::Severity(FaultCode f) {
  switch (f) {
    case FaultCode::kNone:
      return SafetyState::kRunning;
    case FaultCode::kJointLimit:
    case FaultCode::kOverspeed:
    case FaultCode::kSensorTorqueLimit:
    case FaultCode::kCommandTorqueLimit:
    case FaultCode::kNonFiniteCommand:
      return SafetyState::kSafeDamping;
    case FaultCode::kNonFiniteMeasurement:
    case FaultCode::kStaleFrame:
    case FaultCode::kStuckCounter:
    case FaultCode::kEmergencyStop:
      return SafetyState::kSafeTorqueOff;
  }
  return SafetyState::kSafeTorqueOff;  // unknown code: the safest
}

void SafetySupervisor::Reset() {
  out_ = SafetyOutput{};
  // Counter tracking is kept on purpose: a stuck device trips again on the next tick.
}

void SafetySupervisor::Raise(FaultCode f, uint32_t joint_bit) {
  if (out_.fault_mask == 0) out_.first_fault = f;
  out_.fault_mask |= 1u << static_cast<int>(f);
  out_.joint_mask |= joint_bit;
  const SafetyState s = Severity(f);
  if (static_cast<int>(s) > static_cast<int>(out_.state)) out_.state = s;
}

void SafetySupervisor::CheckJoint(const JointSafetyLimits& lim, const JointSafetyInput& j,
                                  uint32_t bit, CounterTrack* track) {
  // Watchdog: age and counter.
  if (!std::isfinite(j.age_s) || j.age_s < 0) Raise(FaultCode::kNonFiniteMeasurement, bit);
  else if (j.age_s > cfg_.max_age_s) Raise(FaultCode::kStaleFrame, bit);
  if (track->seen && j.counter == track->last) {
    if (++track->repeats > cfg_.max_counter_repeats) Raise(FaultCode::kStuckCounter, bit);
  } else {
    track->repeats = 0;
  }
  track->seen = true;
  track->last = j.counter;

  // Measurements. Comparisons are written so that NaN never passes as "in range".
  if (!std::isfinite(j.q) || !std::isfinite(j.qd)) {
    Raise(FaultCode::kNonFiniteMeasurement, bit);
  } else {
    if (!(j.q >= lim.q_min + lim.q_margin && j.q <= lim.q_max - lim.q_margin))
      Raise(FaultCode::kJointLimit, bit);
    if (!(std::abs(j.qd) <= lim.qd_max)) Raise(FaultCode::kOverspeed, bit);
  }
  if (!std::isfinite(j.tau_sensor) || !std::isfinite(j.tau_cmd)) {
    Raise(FaultCode::kNonFiniteCommand, bit);
  } else {
    if (!(std::abs(j.tau_sensor) <= lim.tau_sensor_max)) Raise(FaultCode::kSensorTorqueLimit, bit);
    if (!(std::abs(j.tau_cmd) <= lim.tau_cmd_max)) Raise(FaultCode::kCommandTorqueLimit, bit);
  }
}

SafetyOutput SafetySupervisor::Update(const SafetyInput& in) {
  CheckJoint(cfg_.hip, in.hip, kHipBit, &hip_track_);
  CheckJoint(cfg_.knee, in.knee, kKneeBit, &knee_track_);
  if (in.emergency_stop) Raise(FaultCode::kEmergencyStop, 0u);

  switch (out_.state) {
    case SafetyState::kRunning:  // every check passed: the command is finite and within limits
      out_.tau_hip = in.hip.tau_cmd;
      out_.tau_knee = in.knee.tau_cmd;
      break;
    case SafetyState::kSafeDamping:
      out_.tau_hip = DampingTorque(cfg_.hip, in.hip.qd);
      out_.tau_knee = DampingTorque(cfg_.knee, in.knee.qd);
      break;
    case SafetyState::kSafeTorqueOff:
      out_.tau_hip = out_.tau_knee = 0.0;
      break;
  }
  return out_;
}

}  // namespace exotwin::controller
