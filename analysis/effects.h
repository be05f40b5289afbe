// Model extensions (DESIGN.md "Effects") applied on top of the rigid twin's torques.
#pragma once
#include <vector>

#include "analysis/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// Joint index of an effect ("hip" -> 0, "knee" -> 1).
int EffectJoint(const Effect& e);

// Adds the link-side effects to tau_R[j] (actuator torque, N m) for the kinematics `kin`, then forms
// the sensor reading tau_S = -tau_R and applies the sensor effects (offset, gain, delay). `params`
// gives L1 and g for gravity_error. Throws InputError for an effect it cannot apply.
void ApplyEffects(const LegParams& params, const Kinematics& kin, std::vector<double> tau_R[2],
                  std::vector<double> tau_S[2]);

}  // namespace exotwin
