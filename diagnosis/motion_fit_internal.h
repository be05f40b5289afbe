// The motion fit's parts (motion_fit.h), shared by its files and by nothing else:
//   motion_problem.cc     MotionProblem: the records, rollouts, Jacobians, weighted errors;
//   motion_candidates.cc  the candidates, EffectsOf, TorqueValues, the friction's form, the effects'
//                         order (each family's part through its fit row, fit_families.h);
//   motion_refine.cc      the numerics of steps 2-4: weighted residual and Jacobian, Refine, RefineOne,
//                         LeftOutThetas;
//   motion_rounds.cc      the phases of steps 2-5 (MotionFit::Rounds, ConfirmTorqueNamed);
//   motion_fit.cc         DiagnoseByMotion and the phases of steps 1, 6, 7 and the scores.
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_columns.h"
#include "diagnosis/diagnose_select.h"
#include "diagnosis/motion_fit.h"

namespace exotwin {
namespace motion {

inline constexpr const char* kJoint[2] = {"hip", "knee"};

using Part = MotionProblem::Part;

// ---------------------------------------------------------------------------------------------------
// The records (motion_problem.cc).

// RMS of v about its mean; 0 when v is empty.
double RmsAboutMean(const std::vector<double>& v);
// The restart state's cutoff of a record (motion_fit.h): DiagnoseOptions::motion_cutoff_hz, at most a
// tenth of the record's sample rate (a fifth of its Nyquist frequency).
double MotionCutoff(const DiagnoseOptions& opt, const MeasuredData& data);
// The motion fit's checks of one record (motion_fit.h DiagnoseByMotion): returns the split (first
// held-out sample) and whether the torque reading drives it (else cmd_*).
size_t CheckMotionRecord(const LegParams& params, const MeasuredData& data, const DiagnoseOptions& opt, bool* by_reading);

// ---------------------------------------------------------------------------------------------------
// The candidates (motion_candidates.cc).

// The values of a torque-named effect as the candidate's parameters (into *theta); false if none.
bool TorqueValues(const MotionProblem& P, const Effect& e, Eigen::VectorXd* theta);
// The candidate of the torque fit's effect fx (CandidateIndex), -1 if none.
int CandidateOf(const MotionProblem& P, const Effect& fx);
// D->effects in order (the link effects first, each group by explained_pct) and D->extended: `params`
// with them, the sensor effects in the order the rollouts apply them (offset, gain, delay).
void ExtendedTwin(const LegParams& params, Diagnosis* D);
// TorqueValues of every effect of `torque` that is a candidate of `chosen` (the same name, joint and,
// for gravity_error, axis), into *theta; false if none is.
bool TorqueValuesOfSet(const MotionProblem& P, const std::vector<DiagnosedEffect>& torque, const std::vector<int>& chosen,
                       Eigen::VectorXd* theta);

// ---------------------------------------------------------------------------------------------------
// The numerics (motion_refine.cc).

// The weighted SSE of a rollout on a part, both joints; infinite where the rollout failed.
double Cost(const MotionProblem& P, const MotionProblem::Rollout& ro, Part part);
// Stacked row indices (records stacked, 2 m each) of a part, rows of weight 0 left out.
std::vector<Eigen::Index> PartRows(const MotionProblem& P, Part part);
// Weighted residual (measured - simulated) on `idx` of a rollout.
Eigen::VectorXd WeightedResidual(const MotionProblem& P, const MotionProblem::Rollout& ro,
                                 const std::vector<Eigen::Index>& idx);
// Every stacked row's weight (MotionProblem::weight(r, j) of its record and joint).
Eigen::VectorXd RowWeights(const MotionProblem& P);
// Autocorrelation length (rows) of the weighted fit-part residual: the longest over records and
// joints, at most a window's rows.
double ResidualAutocorrelation(const MotionProblem& P, const MotionProblem::Rollout& ro, double window_rows);
// The weighted Jacobian of the fit rows (PartRows(P, kFit), rows weighted as RowWeights) of
// parameters `cols` at theta, whose rollout (fit part at least) is `at`.
Eigen::MatrixXd WeightedFitJacobian(const MotionProblem& P, const Eigen::VectorXd& theta, const MotionProblem::Rollout& at,
                                    const std::vector<int>& cols);
// Each record left out in turn: the values of `cols` one Gauss-Newton step from theta on the other
// records' fit parts (J, e: the weighted Jacobian and residual of the fit rows at theta), inside the
// box; the rest of theta as it is. Where without a record the values are not identifiable, that
// record's index in *unidentifiable (else -1) and an empty result.
std::vector<Eigen::VectorXd> LeftOutThetas(const MotionProblem& P, const Eigen::VectorXd& theta,
                                           const std::vector<int>& cols, const Eigen::MatrixXd& J,
                                           const Eigen::VectorXd& e, int* unidentifiable);

struct Refined {
  Eigen::VectorXd theta;
  double cost = INFINITY;
  Eigen::MatrixXd J;  // weighted, fit rows x cols, at theta
  Eigen::VectorXd e;  // weighted residual there
};

// Projected Levenberg-Marquardt on parameters `cols` (motion_fit.h step 4), from the best of `starts`.
// With `jacobian` false, Refined::J and ::e are left empty where the last step moved theta (no rollouts
// for a Jacobian nobody reads).
Refined Refine(const MotionProblem& P, const std::vector<int>& cols, const std::vector<Eigen::VectorXd>& starts,
               int iterations = kMotionLmIterations, bool jacobian = true);

// One parameter k refined alone (motion_fit.h step 3's screening fit) by the secant method on the
// fit part's weighted least squares: the derivative of the simulated angles is the secant through the
// last two rollouts (the first: from `base`, theta's own rollout, to `start`), the step Gauss-Newton's
// on it, clamped to the box; one rollout per iteration, at most `iterations`, fewer when the predicted
// decrease falls below the refinement's stopping rule. Returns the best value seen (theta[k] itself
// when nothing lowers the cost).
double RefineOne(const MotionProblem& P, int k, const Eigen::VectorXd& theta, const MotionProblem::Rollout& base,
                 double start, int iterations);

// ---------------------------------------------------------------------------------------------------
// The phases (motion_rounds.cc, motion_fit.cc).

// The candidates of a set in words, "the model given" for none.
std::string Labels(const MotionProblem& P, const std::vector<int>& set);
// A candidate's fitted value as the effect it names, in that effect's unit (EffectsOf: a strap's
// stiffness 1 / compliance, a ripple's amplitude and phase); where its parameters name no effect (0, a
// dead band or strap below the plant's floor, the constant input torque of a record driven by its
// commands) the parameters themselves.
std::string ValueText(const MotionProblem& P, const Candidate& cand, const Eigen::VectorXd& theta);

// One run of the motion fit (DiagnoseByMotion, motion_fit.h "Method"): the state its phases hand on,
// each phase a method, called once in this order: the constructor (set-up, step 1), Rounds (steps
// 2-5), ConfirmTorqueNamed (step 5's last part), HeldOutGate (step 6), Intervals (step 7), ScoreTwins,
// ListTorqueOnly, ScoreTorqueFitTwin, FindUnexplained, Finish. The members are named as in the
// method's text (P the problem, T the torque fit, D the diagnosis being filled, theta the current
// values, at their rollout, chosen the current set).
// A least squares' normal equations summed per block of rows (A[b], g[b]) and per fifth (As, gs).
struct BlockGrams {
  std::vector<Eigen::MatrixXd> A, As;
  std::vector<Eigen::VectorXd> g, gs;
  BlockGrams(size_t blocks, Eigen::Index p);
  // Row x (its columns) with residual e, in block b and fifth f.
  void Add(const Eigen::VectorXd& x, double e, size_t b, size_t f);
};

// Step 7's resamples of a least squares (motion_spread.cc): the solution of each of kSpreadBootstraps
// block bootstraps (as many blocks drawn with replacement as there are, kSpreadSeed) and of the rows
// with each fifth left out, mapped by `values` to n values (false: not defined there); per value the
// bootstraps' standard deviation into sd, the least and largest with a fifth left out into lo, hi
// (NaN: fewer than two bootstraps defined, or no fifth).
using ValuesOf = std::function<bool(const Eigen::VectorXd& solution, std::vector<double>* v)>;
void Resample(const BlockGrams& G, size_t n, const ValuesOf& values, std::vector<double>* sd,
              std::vector<double>* lo, std::vector<double>* hi);

class MotionFit {
 public:
  // Step 1: the records checked, the torque fit (no simulation), the problem, the given twin's rollout.
  MotionFit(const LegParams& params, const std::vector<const MeasuredData*>& records, const DiagnoseOptions& opt);
  // Steps 2-5: linearize at theta, screen, select, refine on the plant, until the chosen set repeats
  // (kMotionOuterSteps rounds at most); then the rounds' best set and the exchanges.
  void Rounds();
  // Step 5: the torque fit's effects put to the plant, each taken where the plant agrees.
  void ConfirmTorqueNamed();
  // Step 6: ranges and the exact held-out gate; leaves `at` the extended twin's rollout (both parts).
  void HeldOutGate();
  // Step 6b: where the torque fit's twin replays the held-out rows better than kTorqueTwinTolerance
  // times the current set's RMS error at a joint, the torque fit's effects in its place (refined on
  // the fit part, added to the set, or at the torque fit's values), the gate then read against that
  // twin.
  void TorqueTwinFloor();
  // Step 7: the weights of the extended twin's misfit, the values refined under them, the 95 %
  // intervals, D.effects and D.extended.
  void Intervals();
  // Step 7's spread: each named effect's value one Gauss-Newton step from theta (the final Jacobian
  // and residual, `last`) on resampled fit rows, a block bootstrap over blocks of a window's rows
  // (kSpreadBootstraps draws, kSpreadSeed) and each fifth of every record's fit rows left out in turn;
  // into D.effects' spread_sd, spread_lo, spread_hi.
  void Spread();
  // The same for the values step 6b held at the torque fit's: that fit resampled (its least squares on
  // its candidate columns at its cutoff and weights, the records prepared as its stage 2 does; blocks
  // as many per record as the motion fit's fit-part windows), each resample's change of a value added
  // to the value reported. Searched ripples and terms are not among the columns: left out of that fit.
  void TorqueFitSpread();
  // Whether every parameter of candidate c is held by step 6b (at the torque fit's value).
  bool Held(int c) const;
  // The given vs the extended twin on the held-out parts and on every whole record left out
  // (D.records, D.joints, D.left_out, D.simulation), the plotted series.
  void ScoreTwins();
  // D.torque_only: what the torque fit names and the motion fit does not, with its held-out change.
  void ListTorqueOnly();
  // SimulationScores::torque_fit_*: the torque fit's twin on the same rows.
  void ScoreTorqueFitTwin();
  // D.unexplained: the structure the extended twin leaves in the first record's held-out simulated
  // angle (StructureLeft, diagnose_unexplained.h): its scored held-out rows in time order (the windows
  // joined), the white noise from the first differences of consecutive samples, the floor
  // kUnexplainedFloorAngle, 15 % of that record's own held-out error of the model given.
  void FindUnexplained();
  // The simulation's cost in the selection log, the method in words; the diagnosis.
  Diagnosis Finish();

 private:
  // Where the simulation goes, in replays of the records (reported in the selection log).
  enum Stage { kSetUp, kJacobians, kScreening, kRefinement, kGate, kScores, kStages };
  // The replays simulated since the last charge, to stage st.
  void Charge(Stage st);

  // Steps 2-3 (motion_rounds.cc).
  // The Jacobian of every parameter at theta (step 2), the columns of the set's one-parameter effects
  // the secants from the set without them; sets tau_eff.
  Eigen::MatrixXd JacobianAtTheta();
  // The linear model at theta of Jacobian J (step 2): one bank per record, their Grams.
  void Linearize(const Eigen::MatrixXd& J, std::vector<ColumnBank>* banks_out, Grams* g_out);
  // Column k of J replaced by the secant (q(x) - q(theta)) / (x_k - theta_k), rx the rollout at x.
  void Secant(Eigen::MatrixXd* J, int k, const MotionProblem::Rollout& rx, double dx);
  // Step 3's screening: each one-parameter candidate's exact single fit in its column of J; the
  // banks and Grams linearized again where one moved.
  void Screen(Eigen::MatrixXd* J, std::vector<ColumnBank>* banks, Grams* g);
  // Step 4: the chosen set's values refined on the plant from the linear fit `lin` (and the torque
  // fit's); false where it cannot be simulated (the last round's set kept: the rounds stop).
  bool RefineChosen(int round, const ColumnBank& bank, const Fit& lin);
  // Step 5: after the last round, the rounds' refined set of the lowest exact fit-part BIC (unless
  // the rounds converged); true where it is not the last round's.
  bool KeepBestRound(bool converged);
  // Step 5's exchanges, the friction's form and the elimination on the plant, on the current set
  // (the exchanges on the last round's linear model g_last, whose bank is `bank`).
  void Polish(const ColumnBank& bank, int round);
  // Exact BIC of a fit-part cost (Cost, Part::kFit) with k parameters (the selection's effective
  // sample size).
  double ExactBic(double cost, size_t k) const;
  size_t ParameterCount(const std::vector<int>& set) const;
  // Step 5's exchanges on this round's linear model (bank, g), then the friction's form.
  void ExchangeEffects(const ColumnBank& bank, const Grams& g, int round);
  void ExchangeFrictionForm(int round);
  // Step 5's backward elimination on the exact plant, after the exchanges.
  void EliminateOnThePlant(int round);

  // Step 6 (motion_fit.cc).
  // The first chosen effect whose refined value leaves its range (its index, *why), else -1.
  int OutOfRange(std::string* why) const;
  // The chosen effect that the held-out gate drops (its index, *why), else -1; sets `explained`.
  int WeakestEffect(std::string* why);
  // Per set of `thetas` (simulated, both parts, in `ro`): each whole record's unweighted error
  // simulated with the set's values one Gauss-Newton step from them without that record, summed
  // over the records (NaN where not simulated).
  std::vector<std::array<double, 2>> LeftOutErrors(const std::vector<Eigen::VectorXd>& thetas,
                                                   const std::vector<MotionProblem::Rollout>& ro);
  // The first record's held-out part as plotted: time, measured, given and extended twin's angle.
  void PlottedSeries();
  // The parameters standing for the effects `fx` at their values, inside the box (the model given's
  // elsewhere); the effects the plant cannot carry appended to *not_carried (when given) once each.
  Eigen::VectorXd TorqueTwinTheta(const std::vector<Effect>& fx, std::vector<std::string>* not_carried) const;
  // Unweighted RMS simulated-angle error per joint of a rollout on the held-out parts, pooled (rad).
  void HeldOutRms(const MotionProblem::Rollout& ro, double rms[2]) const;

 public:
  // The state between the phases.
  const LegParams& params;
  const std::vector<const MeasuredData*>& records;
  const DiagnoseOptions& opt;
  Diagnosis T;  // the torque fit (step 1)
  MotionProblem P;
  const int n_par;
  const std::vector<Candidate>& cands;
  const bool loo;          // several records: each whole record also left out
  ColumnBank cand_bank;    // the candidates alone (ColumnsOf)
  std::vector<int> all;    // every parameter
  Diagnosis D;
  double cost[kStages] = {0, 0, 0, 0, 0, 0}, mark = 0;
  Eigen::VectorXd zero;              // the model given
  MotionProblem::Rollout given;      // its rollout, both parts
  double window_rows = 0;            // scored rows per window
  Eigen::VectorXd theta;             // the current values
  MotionProblem::Rollout at;         // their rollout
  std::vector<int> chosen, previous; // the current and the last round's set
  Grams g_last;                      // the last round's linear model
  double tau_eff = 1;
  std::vector<std::vector<int>> seen;  // the rounds' sets, sorted
  struct Round {
    std::vector<int> set;
    Eigen::VectorXd theta;
    double cost;  // fit-part cost of the refined set
  };
  std::vector<Round> rounds;
  Eigen::VectorXd wv;                // RowWeights
  std::vector<double> explained;     // per chosen effect: % of the given twin's held-out SSE
  double sse_given_te[2] = {0, 0};   // the given twin's weighted held-out SSE
  Refined last;                      // the last refinement of the chosen set
  bool have_last = false;            // `last` is at theta under the current weights
  std::vector<int> cols;             // the final set's parameters (Intervals)
  std::vector<int> held;             // step 6b's parameters held at the torque fit's values (Intervals
                                     // does not move them; Spread does not resample them)
  std::string floor_note;            // step 6b's outcome in words (SimulationScores::torque_fit_why)
};

}  // namespace motion
}  // namespace exotwin
