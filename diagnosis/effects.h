// Model extensions (DESIGN.md "Effects") applied on top of the rigid twin's torques.
//
// Physical models (the same code is the truth in `generate` and the extended twin in `predict`):
//  - coulomb/viscous friction, inertia_error, joint_stiffness, torque_ripple, passive_moment: the DESIGN formulas
//    added to tau_R of that joint (MuJoCo frictionloss / damping / armature / stiffness analogues).
//  - gravity_error: HJ15 eq. 7 with the distal segment's lumped X (or Y) changed by value.
//  - backlash (dead band of total width b): the encoder sits on the motor side; under load the link
//    rests against one flank, lagging the motor by b/2 in the direction of the transmitted torque:
//    q_link,j = q_j - (b/2) s(tau_R,j), s(x) = tanh(x / kBacklashTorqueWidth). The link's dynamics
//    are evaluated at q_link (closed form, HJ15 eq. 5-7 + P): tau_R += tau(q_link) - tau(q).
//  - series_compliance (strap stiffness k): the compliant part (the human limb when the model has
//    one, else the whole chain behind the transmission) follows the measured exoskeleton angle
//    through a spring: q_c,j = q_j - tau_C,j(q_c)/k, solved per sample by Newton's method. Quasi-static:
//    the deflection's own rates are neglected (valid well below the strap resonance sqrt(k/J), a few
//    Hz for k >= 100 N m/rad, above the 0.3-1.5 Hz of the motions). tau_R += tau_C(q_c) - tau_C(q).
//  - muscle_activity: tau_R += value * sum_ch w_ch env_ch(t), env = EmgEnvelope of column emg_<ch>
//    (fields "w_<ch>", N m per V); value is a dimensionless scale (1 as written by diagnose).
//  - sensor_offset, sensor_gain, sensor_delay act on tau_S = -tau_R, in the order listed.
//  - term (DESIGN.md "Terms beyond the table"): value * expr added to tau_R at its joint (stage link) or
//    to tau_S in the sensor effects' order (stage sensor); expr's tau_R is the rigid torque given (before
//    any effect), its t the time from the record's start.
#pragma once
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "formats/measured_data.h"
#include "model/lumped_params.h"
#include "sim/plant_effects.h"  // CompliantPartTorque, CompliantAngle, kBacklashTorqueWidth

namespace exotwin {

// Adds the link-side effects to tau_R[j] (actuator torque, N m) for the kinematics `kin`, then forms
// the sensor reading tau_S = -tau_R and applies the sensor effects (offset, gain, delay). `params`
// gives L1, g and the lumped parameters for the closed-form terms. tau_R[j] must have kin.t.size()
// samples. Throws InputError for an effect it cannot apply (e.g. muscle_activity without the EMG
// column of a weighted channel). A term's t counts from kin.t_start (the record's first time, kept
// by a window of it; NaN: kin.t[0]).
void ApplyEffects(const LegParams& params, const Kinematics& kin, std::vector<double> tau_R[2],
                  std::vector<double> tau_S[2]);

// EMG envelope (V) of a measured column: dsp::ZeroPhaseEnvelope with a 2nd-order 20 Hz high-pass
// (not the 20-450 Hz band-pass: a measured record may be sampled below 900 Hz) and the 4th-order 2 Hz
// envelope low-pass, padded by up to 1 s at both ends. t strictly increasing with a sample rate above
// 40 Hz (median step). Throws InputError otherwise.
std::vector<double> EmgEnvelope(const std::vector<double>& t, const std::vector<double>& emg);
// The envelopes of several such columns at once (dsp::ZeroPhaseEnvelopes), each EmgEnvelope's bits.
std::vector<std::vector<double>> EmgEnvelopes(const std::vector<double>& t,
                                              const std::vector<const std::vector<double>*>& emg);

}  // namespace exotwin
