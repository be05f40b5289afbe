// Joint-space PD position tracking with optional feed-forward torque and torque saturation
// (the "conventional PD controller" of Hwang & Jeon 2015 sec. 3.1):
//   tau = clamp(tau_ff + Kp (q_ref - q) + Kd (qd_ref - qd), -tau_max, tau_max).
// Real-time path (Update) is allocation- and exception-free and returns a status code.
#pragma once
#include "controller/trajectory.h"

namespace exotwin::controller {

struct PdGains {
  double kp = 0;       // N m/rad, >= 0
  double kd = 0;       // N m s/rad, >= 0
  double tau_max = 0;  // N m, > 0: symmetric saturation of the output torque
};

// Stable integer values (may go on the bus or into logs).
enum class PdStatus : int {
  kOk = 0,
  kSaturated = 1,  // output clamped to +-tau_max
  kNonFinite = 2,  // an input was NaN/inf: output torque is 0
};

class JointPdController {
 public:
  // Gains finite, kp, kd >= 0, tau_max > 0; throws InputError otherwise.
  explicit JointPdController(const PdGains& gains);
  // Torque command (N m) into *tau for reference ref, measured q (rad), qd (rad/s) and
  // feed-forward tau_ff (N m; 0 for none). tau non-null. Never writes NaN.
  PdStatus Update(const JointSetpoint& ref, double q, double qd, double tau_ff, double* tau) const;
  const PdGains& gains() const { return gains_; }

 private:
  PdGains gains_;
};

// The two joints together (hip, knee). The worse status of the two is returned.
class LegPdController {
 public:
  // See JointPdController; throws InputError on bad gains.
  LegPdController(const PdGains& hip, const PdGains& knee);
  // Torques (N m) for both joints; feed-forward may be 0. Pointers non-null.
  PdStatus Update(const JointSetpoint& hip_ref, const JointSetpoint& knee_ref, double q_hip,
                  double qd_hip, double q_knee, double qd_knee, double tau_ff_hip,
                  double tau_ff_knee, double* tau_hip, double* tau_knee) const;
  const JointPdController& hip() const { return hip_; }
  const JointPdController& knee() const { return knee_; }

 private:
  JointPdController hip_, knee_;
};

}  // namespace exotwin::controller
