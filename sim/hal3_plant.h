// The MuJoCo plant of the HAL-3 seated knee (mjcf/hal3_knee.xml, Hayashi et al.; Lee & Sankai):
// one hinge "knee" carrying HAL's shank frame (body hal_shank, with the actuator) and the operator's
// lower leg (body human_shank, welded to it: no cuff compliance). HAL's convention: th = 0 hanging,
// positive = extension. The link obeys HKS05 eq. 4 with sigma = 0:
//   (I_h + I_hu + J_m) thdd + R thd + C sgn(thd) + (mgl_h + mgl_hu) sin th = tau + mu
// where the actuator's viscous R and Coulomb C (tanh-smoothed) are applied by this class, J_m is
// the motor's reflected inertia (MuJoCo armature) and mu is the muscle torque given to Step().
// Units SI (rad, rad/s, N m, kg, m). Every step checks for divergence (SimulationError).
#pragma once
#include <string>

#include "sim/plant.h"

namespace exotwin {

struct Subject;

// One rigid link hanging from the knee: mass (kg), CoM distance from the knee along the link (m),
// sagittal moment of inertia about the CoM (kg m^2).
struct HalLinkInertial {
  double mass = 0, com = 0, Icm = 0;
  double Iknee() const { return Icm + mass * com * com; }  // about the knee, kg m^2
};

struct Hal3PlantParams {
  HalLinkInertial human{4.3, 0.26, 0.14};  // lower leg (shank + foot), replaced per subject
  // HAL-3 shank frame + cuff (our choice, the papers give no values; "the inertia value was small
  // compared to that of a human", Lee & Sankai sec. 5): 1.2 kg at 0.20 m, 0.02 kg m^2.
  HalLinkInertial hal{1.2, 0.20, 0.02};
  double armature = 0.03;      // kg m^2, motor + harmonic drive reflected inertia (our choice)
  double R = 0.8;              // N m s/rad, actuator viscous friction (our choice)
  double C = 0.4;              // N m, actuator Coulomb friction (our choice)
  double coulomb_eps = 0.02;   // rad/s, sgn(thd) ~ tanh(thd / eps)
  double g = 9.81;             // m/s^2
  double I() const { return human.Iknee() + hal.Iknee() + armature; }     // total, kg m^2
  double mgl() const { return g * (human.mass * human.com + hal.mass * hal.com); }  // N m
  double hal_I() const { return hal.Iknee() + armature; }                 // HAL side, kg m^2
  double hal_mgl() const { return g * hal.mass * hal.com; }               // HAL side, N m
};

// Lower leg of a subject (weight, L2) from Dempster as adapted by Winter ("Foot leg": 6.1 % of body
// mass, CoM at 60.6 % of L2, radius of gyration 41.6 % of L2; sim/anthropometry.h), HAL defaults.
Hal3PlantParams Hal3ParamsForSubject(const Subject& s);

class Hal3Plant {
 public:
  // Loads the MJCF (default mjcf/hal3_knee.xml). It needs one hinge "knee", bodies hal_shank and
  // human_shank, and one gear-1 motor on the knee. Throws InputError otherwise.
  explicit Hal3Plant(const std::string& mjcf_path = ShippedModelPath("hal3_knee.xml"));
  ~Hal3Plant();
  Hal3Plant(const Hal3Plant&) = delete;
  Hal3Plant& operator=(const Hal3Plant&) = delete;

  // Writes the inertials, armature and gravity; R and C act in Step(). Throws InputError on
  // non-positive masses / inertias or negative R, C.
  void SetParams(const Hal3PlantParams& p);
  const Hal3PlantParams& params() const { return p_; }

  // State th (rad), thd (rad/s) at time t (s).
  void Reset(double th, double thd, double t = 0.0);
  // One physics step (1 ms): motor torque tau (N m, clamped to the model's ctrlrange) and the
  // operator's muscle torque mu (N m, + extension). Throws SimulationError on divergence.
  void Step(double tau_motor, double tau_muscle);

  double th() const;
  double thd() const;
  double thdd() const { return thdd_; }        // acceleration of the last step, rad/s^2
  double time() const;
  double timestep() const;
  double applied_motor() const { return tau_applied_; }  // motor torque of the last step after clamping
  // Torque HAL's frame applied to the operator's lower leg during the last step (N m, + extension):
  // what an ideal strain gauge between actuator and cuff reads (Hayashi Fig. 6):
  //   tau + tau_limit - R thd - C sgn(thd) - mgl_h sin th - (I_h + J_m) thdd.
  double interaction_torque() const { return tau_int_; }

 private:
  void CheckDivergence(const char* where);
  std::string path_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  int dof_ = -1, hal_body_ = -1, human_body_ = -1;
  Hal3PlantParams p_;
  double thdd_ = 0, tau_int_ = 0, tau_applied_ = 0;
};

}  // namespace exotwin
