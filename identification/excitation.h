// Exciting trajectories for the identification protocol (Hwang & Jeon 2015 sec. 3.3: sums of
// harmonic sines and cosines, hip 5..40 deg, knee -5..-70 deg, speeds up to about 120 / 165 deg/s)
// and their design for a well-conditioned regressor (issue 5, item 5).
#pragma once
#include <cstdint>
#include <vector>

#include "identification/identification.h"
#include "model/lumped_params.h"

namespace exotwin {

// q(t) = q0 + sum_i a_i sin(2 pi k_i f0 t) + b_i cos(2 pi k_i f0 t); period 1/f0.
struct HarmonicTrajectory {
  double f0 = 0.1;         // Hz, fundamental
  double q0 = 0;           // rad, offset
  std::vector<int> k;      // harmonic numbers (frequencies k_i f0, Hz)
  std::vector<double> a, b;  // rad, same size as k
  // Angle (rad), velocity (rad/s) and acceleration (rad/s^2) at time t (s).
  void Eval(double t, double* q, double* qd, double* qdd) const;
};

// A patient's safety limits for the moving joint.
struct JointLimits {
  double q_min = 0, q_max = 0;  // rad
  double qd_max = 0;            // rad/s, peak speed
  double tau_max = 0;           // N m, peak actuator torque |tau_R| (0 = unchecked)
};

// Paper ranges: hip 5..40 deg, 120 deg/s; knee -70..-5 deg, 165 deg/s (sec. 3.3). Torque limits
// (ours): hip 100 N m, knee 70 N m (the relaxed knee at -5 deg with the hip at 90 deg already needs
// ~60 N m, half of it the hamstrings' passive torque).
JointLimits DefaultLimits(IdConfiguration c);

// Scales and offsets `shape` (its relative a_i, b_i) so that it spans [q_min, q_max] over one period;
// when that would exceed qd_max, the amplitude shrinks until the peak speed is qd_max, centered in
// the range. Precondition: a non-constant shape.
HarmonicTrajectory FitToLimits(const HarmonicTrajectory& shape, const JointLimits& lim);

// The default (not optimized) excitation: harmonics at 0.3, 0.5, 0.8, 1.1, 1.5 Hz (f0 = 0.1 Hz),
// amplitudes 1/k with phases from `seed`, fitted to DefaultLimits(c).
HarmonicTrajectory DefaultExcitation(IdConfiguration c, uint64_t seed = 1);

// Condition number of the column-scaled step regressor (knee row [J2 X2 Y2] with the hip exactly at
// 90 deg, or hip row [J1 X1 Y1] with the knee at -90 deg) over one period sampled at 200 Hz.
double ExcitationCondition(const HarmonicTrajectory& tr, IdConfiguration c, double L1, double g = 9.81);

// Tolerance-normalized standard error per unit torque noise: the RMS over [J, X, Y] of
// sqrt((W'W)^-1_jj) / tol_j with tol = 2 % of the nominal J and X of the system being identified
// (the human when nominal has one, else the exo) and 0.01 kg m for Y (the recovery criteria), W the
// step regressor over one period at 200 Hz (an A-optimal criterion in units of the tolerances;
// smaller is better; the expected error in tolerances is sigma * this / sqrt(N / 2000)).
double ExcitationRelativeError(const HarmonicTrajectory& tr, IdConfiguration c, const LegParams& nominal);

// Peak |tau_R| (N m) of the moving joint along one period for the model `nominal` (relaxed, with
// its human and passive model when present), the other joint held at 90 / -90 deg.
double PeakTorque(const HarmonicTrajectory& tr, IdConfiguration c, const LegParams& nominal);

// What DesignExcitation minimizes: the condition number of the column-scaled regressor (blind to the
// excitation's energy), or ExcitationRelativeError (the expected error against the recovery limits).
enum class ExcitationCriterion { kCondition, kRelativeError };

struct ExcitationDesignOptions {
  ExcitationCriterion criterion = ExcitationCriterion::kCondition;
  JointLimits limits;          // of the moving joint (tau_max checked with `nominal`)
  LegParams nominal;           // model used for the torque limit
  int restarts = 3;            // random starts besides the default excitation
  int iterations = 400;        // (1+1)-evolution-strategy iterations per start
  uint64_t seed = 7;
};

struct ExcitationDesign {
  HarmonicTrajectory trajectory;
  double condition = 0, initial_condition = 0;  // optimized, and of DefaultExcitation
  double relative_error = 0, initial_relative_error = 0;  // ExcitationRelativeError, same two
  double peak_speed = 0, peak_torque = 0;       // rad/s, N m of the optimized trajectory
};

// Optimizes the a_i, b_i of DefaultExcitation(c)'s harmonics for the smallest opt.criterion
// (ExcitationCondition or ExcitationRelativeError) within the joint range, speed and torque limits (every candidate is fitted by FitToLimits; a
// candidate over tau_max is rejected). Seeded (1+1)-ES with the 1/5 success rule, deterministic.
ExcitationDesign DesignExcitation(IdConfiguration c, const ExcitationDesignOptions& opt);

}  // namespace exotwin
