// Joint selection of the effects that explain a residual (used by Diagnose, diagnose.h): least
// squares on Gram matrices of the candidate columns (diagnose_columns.h) pooled over the records of
// one device, with a time split per record and leave-one-record-out validation.
//
// Method (forward selection with backward elimination, the effects always fitted together):
//  - a step adds the candidate that lowers the Bayesian information criterion most (effective
//    sample size from the residual autocorrelation), provided that the BIC drops by more than
//    kBicMargin, the held-out error at the candidate's joint (last 30 % of every record; and, with
//    several records, every whole record left out in turn) drops by at least kMinHeldoutGain of its
//    current value and by at least (kMinTorqueShare of the measured torque's RMS)^2 (an effect too
//    small to matter is not named), and every
//    effect of the new set is significant (|t| > kMinT) and inside its physical range (Plausible);
//  - the simplest explanation: among the admissible additions at the same joint, one with fewer
//    parameters wins over the best unless the best lowers that joint's held-out error by more than
//    kParsimony of it;
//  - after each addition, effects that no longer earn the BIC margin in the joint fit are removed;
//  - it stops when nothing qualifies, at max_effects, or when a set repeats.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/materiality.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_columns.h"

namespace exotwin {

constexpr double kBicMargin = 10.0;       // BIC drop needed to name an effect (strong evidence)
constexpr double kMinHeldoutGain = 0.05;  // held-out SSE drop needed per added effect (fraction)
constexpr double kMinT = 4.0;             // |coefficient| / standard error
constexpr double kParsimony = 0.05;       // held-out SSE margin a richer explanation must win by
constexpr double kMinTorqueShare = kMaterialShare;  // and by at least (this share of the torque's RMS)^2

// Gram matrices of the weighted columns: train / held-out rows (time split) pooled over records,
// and every record's whole rows (for leave-one-record-out).
struct Grams {
  Eigen::MatrixXd Gtr, Gte[2];  // held-out rows per joint ([0] hip rows, [1] knee rows)
  Eigen::VectorXd btr, bte[2];
  double rrtr = 0, rrte[2] = {0, 0};
  double n_tr = 0, n_eff = 0;
  std::vector<Eigen::MatrixXd> Grec[2];  // per joint, per record, all rows
  std::vector<Eigen::VectorXd> brec[2];
  std::vector<double> rrrec[2];
  double tt_te[2] = {0, 0};  // weighted sum of squares of the measured torque, held-out rows per joint
  std::string scale_name = "torque";  // what tt_te measures, for the selection's words
  size_t records() const { return Grec[0].size(); }
};

// Least-squares fit of a column subset.
struct Fit {
  bool ok = false;
  std::vector<int> cols;
  Eigen::VectorXd coef, se;
  double sse_tr = 0, sse_te = 0, sse_loo = 0, bic = 0;  // held-out sums over both joints
  double sse_te_j[2] = {0, 0}, sse_loo_j[2] = {0, 0};   // per joint
};

// Grams of banks with identical columns (one bank per record).
Grams MakeGrams(const std::vector<ColumnBank>& banks);

// Fits `cols` on the train rows (sse_tr, coefficients, standard errors, BIC), scores the held-out
// rows (sse_te) and, with two records or more and `leave_one_out`, leave-one-record-out (sse_loo: each
// record scored by the fit on all rows of the others). !ok when the normalized Gram is nearly singular.
Fit FitCols(const Grams& g, std::vector<int> cols, bool leave_one_out = true);

// Coefficients of `cols` fitted on all rows of every record but `left_out` (leave-one-record-out).
Eigen::VectorXd FitLeavingOut(const Grams& g, const std::vector<int>& cols, size_t left_out);

// Sign-constrained least squares: minimizes x'Ax - 2 b'x subject to sign[i] x_i >= 0 (sign[i] = +1:
// x_i >= 0, -1: x_i <= 0, 0: free), by the active-set method of Lawson & Hanson (1974, Solving Least
// Squares Problems, ch. 23, NNLS) with free variables. *x: the solution, exactly zero where held at
// its bound; its nonzero and free entries are the unconstrained least squares of those columns (the
// passive set). False when the passive set's normal equations are nearly singular.
bool SolveSigned(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<int>& sign, Eigen::VectorXd* x);

// FitCols under the sign constraints `sign` (one per column of the Grams, SolveSigned's meaning) on
// the train rows: the unconstrained fit of the passive set (the columns held at zero left out: its
// coefficients, standard errors and BIC count the passive columns only, the degrees of freedom of
// a sign-constrained fit; Meyer & Woodroofe 2000, Ann. Statist. 28:1083-1104).
Fit FitColsSigned(const Grams& g, const std::vector<int>& cols, const std::vector<int>& sign);

// FitLeavingOut under the sign constraints `sign` (per column of the Grams): coefficients aligned
// with `cols`, zero where held; empty when unidentifiable.
Eigen::VectorXd FitLeavingOutSigned(const Grams& g, const std::vector<int>& cols, const std::vector<int>& sign,
                                    size_t left_out);

// The columns of the candidates `set` (indices into bank.candidates), sorted, without repeats.
std::vector<int> ColumnsOf(const ColumnBank& bank, const std::vector<int>& set);

double CoefOf(const Fit& f, int col);
double SeOf(const Fit& f, int col);

// What the physical ranges are measured against (DESIGN.md "Effects", ranges): the records' angle
// range and torque per joint, and the twin's own inertia and distal gravity terms.
struct PhysicalScale {
  double q_min[2] = {0, 0}, q_max[2] = {0, 0};  // rad, over every record
  double q_rms[2] = {0, 0};                     // rad, RMS of the angle about its mean, every record
  double tau_max[2] = {0, 0};                   // N m, max |measured torque|
  double tau_C_max[2] = {0, 0};                 // N m, max |torque of the series-compliant part|
  double tau_C_rms[2] = {0, 0};                 // N m, its RMS (strided over every record)
  // N m/rad: J_c w^2, with J_c the compliant part's mean diagonal inertia and w = RMS(qdd) /
  // RMS(qd) the motion's effective angular frequency. The quasi-static strap model holds below the
  // strap's resonance sqrt(k / J_c): strap_dynamics / k = (w / resonance)^2.
  double strap_dynamics[2] = {0, 0};
  double M_jj[2] = {0, 0};                      // kg m^2, the twin's mean diagonal inertia
  double distal_moment[2] = {0, 0};             // kg m, hypot(X, Y) of the segments distal to j
};

// One record's part of the physical scale: its kinematics and measured torque reading per joint
// (N m, the samples of kin->t).
struct ScaleRecord {
  const Kinematics* kin = nullptr;
  const std::vector<double>* tau[2] = {nullptr, nullptr};
};

// The physical scale of the records: angle and torque ranges, the twin's mean M_jj, the compliant
// part's torque and the strap's neglected dynamics J_c w^2 (strided means over every record).
PhysicalScale ScaleOf(const LegParams& params, const std::vector<ScaleRecord>& recs);

// The effect a candidate's fitted coefficients stand for (value, 95 % interval, fields).
DiagnosedEffect ToEffect(const Candidate& c, const Fit& f);
DiagnosedEffect ToEffect(const Candidate& c, const Eigen::VectorXd& coef, const std::vector<int>& cols);

// Inside its physical range? (Sign constraints, DESIGN.md's table of ranges.) `why` says why not.
bool Plausible(const DiagnosedEffect& e, const PhysicalScale& s, std::string* why = nullptr);

// Two candidates that cannot be named together: the same effect at the same joint (gravity_error's X
// and Y axes, one at a time), two families of one exclusive group at the same joint (a dead band and
// a strap: the plant's one internal hinge, EffectFamily::exclusive) or a shared column
// (joint_stiffness's offset and sensor_offset).
bool Conflicts(const Candidate& a, const Candidate& b);

struct SelectionTrace {
  std::vector<std::string> steps;  // in words: what was added or removed, and the scores
};

// Forward selection with backward elimination (header comment). Returns the chosen candidates'
// indices into bank.candidates, in the order they were added, and the joint fit in *fit.
std::vector<int> SelectEffects(const ColumnBank& bank, const Grams& g, const PhysicalScale& scale,
                               int max_effects, bool leave_one_out, Fit* fit, SelectionTrace* trace);

}  // namespace exotwin
