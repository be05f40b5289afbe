#include "controller/pd_controller.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace exotwin::controller {

JointPdController::JointPdController(const PdGains& g) : gains_(g) {
  if (!(std::isfinite(g.kp) && g.kp >= 0)) throw InputError("PdGains: kp must be >= 0 N m/rad");
  if (!(std::isfinite(g.kd) && g.kd >= 0)) throw InputError("PdGains: kd must be >= 0 N m s/rad");
  if (!(std::isfinite(g.tau_max) && g.tau_max > 0))
    throw InputError("PdGains: tau_max must be > 0 N m");
}

PdStatus JointPdController::Update(const JointSetpoint& ref, double q, double qd, double tau_ff,
                                   double* tau) const {
  const double u = tau_ff + gains_.kp * (ref.q - q) + gains_.kd * (ref.qd - qd);
  if (!std::isfinite(u)) {  // any non-finite input (or overflow) ends up here
    *tau = 0.0;
    return PdStatus::kNonFinite;
  }
  *tau = std::clamp(u, -gains_.tau_max, gains_.tau_max);
  return *tau == u ? PdStatus::kOk : PdStatus::kSaturated;
}

LegPdController::LegPdController(const PdGains& hip, const PdGains& knee) : hip_(hip), knee_(knee) {}

PdStatus LegPdController::Update(const JointSetpoint& hip_ref, const JointSetpoint& knee_ref,
                                 double q_hip, double qd_hip, double q_knee, double qd_knee,
                                 double tau_ff_hip, double tau_ff_knee, double* tau_hip,
                                 double* tau_knee) const {
  const PdStatus a = hip_.Update(hip_ref, q_hip, qd_hip, tau_ff_hip, tau_hip);
  const PdStatus b = knee_.Update(knee_ref, q_knee, qd_knee, tau_ff_knee, tau_knee);
  return static_cast<int>(a) > static_cast<int>(b) ? a : b;
}

}  // namespace exotwin::controller
