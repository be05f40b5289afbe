// Virtual impedance of HAL-3 (Lee & Sankai): the actuator compensates the exoskeleton's own inertia,
// viscous friction, gravity moment and Coulomb friction so that the operator feels VIRTUAL values
// instead. HAL convention: th = 0 hanging, + extension; gravity moment mgl sin th.
// Exoskeleton link:  I thdd + B thd + mgl sin th + C sgn(thd) = tau_c + tau_op   (tau_op: operator)
// With tau_c below, the operator feels  I_v thdd + B_v thd + mgl_v sin th + C_v sgn(thd) (+ the
// remaining I - I_v mismatch of the acceleration estimate). Lee & Sankai's criteria: (i) I_v = 0 and
// C_v = 0, (ii) mgl_v = mgl (gravity retained), (iii) B_v a little above 1.56 N m/(rad/s).
// It is also Hayashi's tau_c of HKS05 eq. 6 with I_v = 0, B_v = 0, mgl_v = mgl, C_v = 0.
#pragma once

namespace exotwin::controller {

struct OneLinkImpedance {
  double I = 0;    // kg m^2
  double B = 0;    // N m s/rad
  double mgl = 0;  // N m
  double C = 0;    // Coulomb friction, N m
};

struct VirtualImpedanceConfig {
  OneLinkImpedance actual;   // identified exoskeleton (LS05 eq. 15 for I, B, mgl; C separately)
  OneLinkImpedance target;   // virtual values
  double coulomb_eps = 0.05; // rad/s: sgn(thd) smoothed as tanh(thd / eps) (our choice, avoids chatter)
};

// Lee & Sankai's recommended setting for an exoskeleton `actual`: I_v = 0, C_v = 0, gravity
// retained, B_v = b_v (default 1.56 N m/(rad/s), the paper's minimum of the musculoskeletal moment).
VirtualImpedanceConfig LeeSankaiSetting(const OneLinkImpedance& actual, double b_v = 1.56);

// Compensation torque tau_c (N m) at angle th (rad), velocity thd (rad/s), acceleration estimate
// thdd (rad/s^2):  (I - I_v) thdd + (B - B_v) thd + (mgl - mgl_v) sin th + (C - C_v) tanh(thd/eps).
double CompensationTorque(const VirtualImpedanceConfig& cfg, double th, double thd, double thdd);

// Torque (N m) the operator must supply to move the link along (th, thd, thdd) with the
// compensation on: the virtual impedance it feels (exact when thdd is exact).
double FeltImpedanceTorque(const VirtualImpedanceConfig& cfg, double th, double thd, double thdd);

}  // namespace exotwin::controller
