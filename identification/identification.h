// Off-line least-squares identification of the lumped parameters (HJ15 eq. 4), the four steps of Hwang &
// Jeon 2015 sec. 3.2 (HJ15 eq. 14-21, Appendix A1-A4) with the re-derived signs of model/regressors.cc.
//
// Configurations (DESIGN.md `identify`): knee swing = the knee moves, the hip is held near 90 deg
// (steps 1 and 3); hip swing = the hip moves, the knee is held near -90 deg (steps 2 and 4). A file's
// configuration is told by which joint moves.
//
// Regressor: the held joint is held by a PD controller, so it is near but not exactly at 90 / -90 deg.
// Instead of the paper's step rows (exact only when the held joint is exactly still) each step uses
// the moving joint's row of the full regressor, tau_R = Y(q, qd, qdd) theta + P(q) (HJ15 eq. 3, 8 with
// tau_M = 0), restricted to the three unknown columns, with every known parameter moved to the left:
//   step 1 (R2): knee row, unknown [J2 X2 Y2]_R, nothing known (exo alone)
//   step 2 (R1): hip row,  unknown [J1 X1 Y1]_R, known [J2 X2 Y2]_R from step 1
//   step 3 (H2): knee row, unknown [J2 X2 Y2]_H, known exo, minus P2 (passive model)
//   step 4 (H1): hip row,  unknown [J1 X1 Y1]_H, known exo and [J2 X2 Y2]_H from step 3, minus P1
// This is exact for any state and equals Step1Row..Step4Row (HJ15 eq. 18, A1-A4) when the held joint is
// exactly still at 90 / -90 deg (tests/identification/identification_test.cc).
//
// Solver: HJ15 eq. 21 through the normal equations of the column-scaled regressor W D (D = diag of
// 1/||column||), LDLT in Eigen. Outputs per step: estimate phi, standard errors sqrt(diag(
// sigma^2 (W'W)^-1)) with sigma^2 = |r|^2 / (N - 3), plus, for steps 2 and 4, the propagated
// uncertainty of the step-1/3 values they use (G Sigma G', G = (W'W)^-1 W'A, A the known columns).
// The standard errors assume white residuals; the 20 Hz-filtered derivatives make the residual
// correlated over a few ms, so they can be optimistic (on the synthetic protocol they match the
// observed errors in order of magnitude).
// Condition number: sigma_max / sigma_min of W D (2-norm), invariant to the units of J, X, Y.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "formats/measured_data.h"
#include "identification/passive_selection.h"
#include "core/units.h"
#include "model/lumped_params.h"
#include "model/regressors.h"

namespace exotwin {

// What steps 3-4 fit beyond the paper's rows (all off: Hwang & Jeon 2015 as published). The
// subject's own passive moment and damping: HJ15 subtracts a population curve P^ (eq. 16-17) and
// neglects the relaxed limb's damping; a subject's curve is its own (Silder et al. 2007 fit one per
// subject). The knee cuff: HJ15's rows take the human's knee angle for the encoder's.
struct HumanSideFit {
  double max_knee_compliance = 0;  // rad/N m, the knee cuff's search bound (`--knee-cuff`); 0 = rigid
  bool subject_passive = false;    // per step, the subject's factor on P^ and the link side's damping
};
// The knee cuff search's bound: any strap stiffer than 100 N m/rad.
constexpr double kKneeCuffMaxCompliance = 0.01;

enum class IdConfiguration { kKneeSwing, kHipSwing };
// "knee swing (hip held)" / "hip swing (knee held)".
const char* ConfigurationName(IdConfiguration c);

struct IdentificationOptions {
  double moving_min_range = 10.0 * kRadPerDeg;  // rad, least range (max - min) of the moving joint
  double held_max_range = 5.0 * kRadPerDeg;     // rad, largest range of the held joint
  double trim_s = 0.1;          // s dropped at both ends of every file (derivative-filter edges)
  double cutoff_hz = 20.0;      // Hz, zero-phase Butterworth of the derivatives (sec. 3.2)
  PassiveModel passive = PassiveModel::kRiener1999;  // P^ subtracted in steps 3-4 (HJ15 eq. 16-17)
  PassiveSelectionOptions selection;                 // HJ15 eq. 13, human steps only
  HumanSideFit human_side;                           // steps 3-4 beyond the paper (default: none)
};

// Range (min, max, mean; rad) of both joints of a file.
struct JointRanges {
  double min[2], max[2], mean[2];  // [0] hip, [1] knee
};
JointRanges ComputeJointRanges(const MeasuredData& data);

// Which configuration a file is. Throws InputError naming data.source, both joints' ranges (deg) and
// what was expected when the file fits neither.
IdConfiguration ClassifyConfiguration(const MeasuredData& data, const IdentificationOptions& opt = {});

// Samples of one configuration ready for the regressor: state (rad, rad/s, rad/s^2) and actuator
// torque u = tau_R = -tau_S (N m, HJ15 eq. 8), after derivative estimation, trimming and EMG selection.
struct IdentificationSamples {
  IdConfiguration config = IdConfiguration::kKneeSwing;
  std::vector<std::string> sources;
  std::vector<double> q[2], qd[2], qdd[2], u[2];
  // Steps 3-4 with the knee cuff fitted, prepared with the known exoskeleton: the torque the knee cuff
  // carries to the human's lower leg, tau_C = u_knee - the exoskeleton's knee row at the measured state
  // (N m; HJ15 eq. 8 split at the cuff), as recorded and its two rates by the angles' derivative chain.
  // Empty otherwise.
  std::vector<double> tau_c, tau_c_d, tau_c_dd;
  size_t total = 0;  // samples in the files before trimming and selection
  size_t size() const { return u[0].size(); }
};

// Appends the samples of one file (derivatives by DeriveKinematics with opt.cutoff_hz, trim at both
// ends; with select_passive, only samples passing HJ15 eq. 13). With `exo` (steps 3-4: L1, g and the
// identified exoskeleton), also the cuff torque tau_C and its rates. Precondition: data is of
// configuration into->config (use ClassifyConfiguration). Throws InputError if the trim leaves nothing.
void AppendSamples(const MeasuredData& data, bool select_passive, const IdentificationOptions& opt,
                   IdentificationSamples* into, const LegParams* exo = nullptr);

// One row u* = w' phi (HJ15 eq. 18) of step 1..4 from the full regressor at any state (q, qd, qdd) with
// actuator torque u (N m, the moving joint's tau_R): w = the moving joint's row of FullRegressor at
// the unknown columns, u* = u - (that row) . known - P_row(q) (P only in steps 3-4, model `passive`).
// `known` as in SolveStep. Equals Step1Row..Step4Row when the held joint is exactly still at 90 / -90.
StepRow GeneralStepRow(int step, double L1, double g, const Vector6& known, PassiveModel passive,
                       const Eigen::Vector2d& q, const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                       double u);

// Steps 3-4's rows beyond the paper's. A compliant knee cuff (DESIGN.md series_compliance: the strap
// between the exoskeleton's lower leg and the human's): the human's knee angle is the exoskeleton's
// less knee_compliance x tau_C (its rates likewise, the samples' tau_c_d, tau_c_dd), the human's rows
// (unknown, known distal, passive P^) are evaluated at the human's state and the exoskeleton's known
// row at the measured one. subject_passive: two more unknown columns, P^'s row at the human's state
// (its coefficient the subject's factor on P^, instead of P^ subtracted) and the human's velocity of
// the moving joint (the link side's viscous damping, N m s/rad; where it comes out negative it is held
// at 0 and the step solved without it: a negative damping would feed energy, and a plant refuses it).
struct HumanSideRows {
  double knee_compliance = 0;     // rad/N m (1 / the strap's stiffness); 0 = rigid
  Vector6 exo = Vector6::Zero();  // the exoskeleton's part of `known` (model/regressors.h layout)
  bool subject_passive = false;
};

// Result of one step (HJ15 eq. 18-21).
struct StepEstimate {
  int step = 0;                                  // 1..4 (HJ15 eq. 14-17)
  std::string segment;                           // "R2", "R1", "H2", "H1"
  Eigen::Vector3d phi = Eigen::Vector3d::Zero();  // [J, X, Y]: kg m^2, kg m, kg m
  Eigen::Vector3d se = Eigen::Vector3d::Zero();   // standard errors, same units
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // covariance of phi
  double condition_number = 0;                   // of the column-scaled regressor (all its columns)
  // HumanSideRows::subject_passive: the subject's factor on P^ and the damping (N m s/rad), with
  // their standard errors; else 1 and 0, not fitted.
  double passive_factor = 1, passive_factor_se = 0, damping = 0, damping_se = 0;
  double residual_rms = 0;                       // N m
  double held_mean = 0;                          // rad, mean angle of the held joint
  size_t samples_used = 0, samples_total = 0;
  std::vector<std::string> sources;
};

// One step on prepared samples. `known` holds every parameter already known in the layout of
// model/regressors.h ([J1 J2 X1 X2 Y1 Y2] of the combined system, the unknown entries zero);
// `known_cov` (may be null) the covariance of the known distal [J2 X2 Y2] (steps 2 and 4); `rows` (may
// be null; steps 3-4) the rows beyond the paper's. Precondition: samples.size() >= 3 (5 with
// subject_passive), and samples' tau_c filled where rows->knee_compliance > 0; throws InputError if
// the regressor is rank deficient.
StepEstimate SolveStep(int step, const IdentificationSamples& samples, double L1, double g,
                       const Vector6& known, PassiveModel passive,
                       const Eigen::Matrix3d* known_cov = nullptr, const HumanSideRows* rows = nullptr);

struct IdentificationResult {
  LegParams params;                // exo (+ human, passive) identified; L1, g as used
  std::vector<StepEstimate> steps;  // steps 1-2 or 3-4
  // Steps 3-4: the knee cuff's compliance both steps used (rad/N m, 0 = rigid) and step 3's residual
  // RMS (N m) with a rigid cuff. The identified model (params) carries no strap: the cuff is for
  // `diagnose` to name from motion. With subject_passive, params.effects carry the subject's
  // passive_moment (factor - 1) and viscous_friction per joint (steps 3 and 4's).
  double knee_compliance = 0, rigid_cuff_residual_rms = 0;
};

// Steps 1-2: the exoskeleton alone from the knee-swing and hip-swing samples. L1 (m), g (m/s^2).
IdentificationResult IdentifyExo(const IdentificationSamples& knee, const IdentificationSamples& hip,
                                 double L1, double g);

// Steps 3-4: the human with known.exo, known.L1, known.g; P^ = `passive`; `fit` beyond the paper.
// With fit.subject_passive every step has the two more columns of HumanSideRows (P^ must not be
// kNone). With fit.max_knee_compliance > 0 (and the samples' tau_c filled) the knee cuff's compliance
// c in [0, max] is fitted first: the one that minimizes step 3's residual (golden-section search to
// 1e-4 of max; kept where its RMS deflection is material, core/materiality.h, against the knee angle's
// RMS about its mean), then steps 3 and 4 are solved with it. A strap's deflection, tau_C / k,
// otherwise biases the human's knee segment (X2 -4.6 % at 1100 N m/rad on S1): the regressor would be
// evaluated at the exoskeleton's angle instead of the human's.
IdentificationResult IdentifyHuman(const IdentificationSamples& knee, const IdentificationSamples& hip,
                                   const LegParams& known, PassiveModel passive, const HumanSideFit& fit = {});

// Whole pipeline on files (any order, one or more per configuration): classifies, prepares, solves.
// known == nullptr: steps 1-2 with thigh length L1; else steps 3-4 with known->exo (L1 from known).
// Throws InputError when a configuration is missing or a file fits neither.
IdentificationResult Identify(const std::vector<MeasuredData>& files, const LegParams* known,
                              double L1, const IdentificationOptions& opt = {});

// The `identification:` block of MODEL.yaml (top-level YAML text, ends with a newline).
std::string IdentificationYaml(const IdentificationResult& r, const IdentificationOptions& opt);

}  // namespace exotwin
