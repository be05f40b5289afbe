// EMG-to-torque calibration of Hwang & Jeon 2015 (after Olney & Winter 1985), issue 6 item 5:
// isometric alpha by least squares (HJ15 eq. 23-25), dynamic beta and gamma given alpha (HJ15 eq. 26-28), and
// the R^2 / normalized RMS figures of Tables 6-7. Off-line: whole records, one sample per 1/fs. The
// envelopes (dsp::LinearEnvelopeZeroPhase) and the MVC (dsp::MvcOfTrials) are dsp/'s.
//
// Units (see sim/muscles.h): LE = envelope / MVC (fraction of MVC, 0..1), alpha in N m at MVC (the
// paper's alpha x 100 if its LE is in % MVC), beta in 1/rad, gamma in s/rad (BetaPerDeg / GammaPerDegS
// give the paper's 1/deg, 1/(deg/s)). Joint 0 = hip, 1 = knee; EXOwheel signs (HJ15 eq. 23-24).
#pragma once
#include <vector>

#include <Eigen/Core>

#include "sim/muscles.h"

namespace exotwin {

// Goodness of fit as in Tables 6-7. The paper does not define them; we use R^2 = 1 - SS_res/SS_tot
// (about the measured mean) and NRMS = 100 RMS(predicted - measured) / (max - min of measured), %.
struct FitQuality {
  double r2 = 0;
  double nrms_pct = 0;
};
// Precondition: same non-zero length, measured not constant.
FitQuality Quality(const std::vector<double>& measured, const std::vector<double>& predicted);

// Resting level of a linear envelope (V): its mean over the relaxed samples [a, b) (a < b <= size).
double RestLevel(const std::vector<double>& env, size_t a, size_t b);

// Normalized linear envelope LE (fraction of MVC, dsp::NormalizeToMvc) of each channel at sample k:
//   LE = (env - rest) / (mvc - rest)   (env: one envelope per channel in Muscle order, V)
// rest = 0 gives the paper's plain env / MVC. A relaxed electrode/amplifier floor left in LE reads as a
// constant phantom torque alpha x rest / MVC in HJ15 eq. 23-27 (see tests/emg/emg_calibration_test.cc).
MuscleVec NormalizedEnvelope(const std::vector<std::vector<double>>& env, size_t k, const MuscleVec& rest,
                             const MuscleVec& mvc);

// Isometric torque of HJ15 eq. 23 (joint 0) or (24) (joint 1): sum_m sign(m, j) alpha_m LE_m (N m).
double IsometricTorque(int joint, const MuscleVec& alpha, const MuscleVec& le);

struct AlphaFit {
  MuscleVec alpha = MuscleVec::Zero();  // N m at MVC; 0 for muscles not spanning the joint
  FitQuality quality;
};
// HJ15 eq. 25: least squares of alpha for `joint` against the measured torque tau (N m; the sensor
// reads the muscular torque alone when the joint is fixed). le and tau same length.
AlphaFit FitIsometricAlpha(int joint, const std::vector<MuscleVec>& le, const std::vector<double>& tau);

// Dynamic torque of HJ15 eq. 26/27 (N m) with angle q (rad), velocity qd (rad/s).
double DynamicTorque(int joint, const MuscleVec& alpha, double beta, double gamma, double theta_c,
                     const MuscleVec& le, double q, double qd);

struct BetaGammaFit {
  double beta = 0;   // 1/rad
  double gamma = 0;  // s/rad
  FitQuality quality;
  double beta_per_deg() const { return beta / kDegPerRad; }    // the paper's unit
  double gamma_per_deg_s() const { return gamma / kDegPerRad; }
};
// HJ15 eq. 28: with alpha fixed, HJ15 eq. 26/27 is linear in (beta, gamma):
//   tau = (E - F) + beta (E + F)(q - q_c) - gamma (E + F) qd,  E/F = extensor/flexor sums alpha LE
// (E along +q). Least squares against tau_M = tau_S - tau_PAS. theta_c: HJ15 eq. 27 (0 hip, -pi/2 knee).
BetaGammaFit FitDynamicBetaGamma(int joint, const MuscleVec& alpha, double theta_c,
                                 const std::vector<MuscleVec>& le, const std::vector<double>& q,
                                 const std::vector<double>& qd, const std::vector<double>& tau_M);

}  // namespace exotwin
