// `exotwin diagnose --fit motion` (DESIGN.md "diagnose --fit motion"): the effects that explain where
// the twin's simulated motion departs from the records, chosen and sized by simulating the forward
// plant on them. The torque fit (diagnose.h) sees only what a quasi-static inverse-dynamics residual
// shows; a dead band, a strap or a delay lives in the dynamics and shows in the motion.
//
// What is fitted: theta, the values of the candidate effects, minimizing over the fit part of every
// record
//     S(theta) = sum_records r sum_joints j sum_scored samples i  w_rj^2 (q_j(t_i) - qsim_j(t_i; theta))^2
// where qsim is the angle of the forward plant replay uses (diagnosis/replay.h MakeReplayPlant / Replay:
// the model given + the candidates' effects, carried as sim/plant_effects.h says), driven by the
// record's actuator torque (the torque reading with the model's and the candidates' sensor effects
// inverted, ActuatorTorqueFromReading; the cmd_* columns where the reading is zero throughout) and
// held between samples or interpolated (ReplaySeries::hold: whichever the model given, alone or with
// the torque fit's effects, follows closer on the fit parts: a record of the twin's own joint modules
// is held, MotionProblem::hold),
// restarted from the measured state (the measured angle and its velocity derived at
// DiagnoseOptions::motion_cutoff_hz, at most a tenth of the record's sample rate, zero-phase; replay.h)
// in quiet windows of DiagnoseOptions::replay_horizon_s (replay.h "windows": restarted and scored where
// the motion has no fast content the restart velocity misses, a dead band's knocks): multiple shooting,
// each window scored on its samples after the restart. The fit part is the first
// 1 - holdout_fraction of every record's time, the held-out part the rest; no window straddles the
// split.
// The torque reading is the input, so it is no output here (the twin's sensor reads the motor
// torque, HJ15 eq. 8: the simulated reading would be the input itself); the outputs are the angles.
// Output weights: w_rj = 1 / (the misfit level at joint j on record r's fit part: the lower RMS
// simulated-angle error of the model given and of the model with the torque fit's effects): weighted
// least squares, each output its own misfit level, estimated by the better twin at hand before the fit
// (the given twin's error at a joint it misses by a lacking friction, 28 deg at the real rig's knee
// against 8 at its hip, overstates the level the fit ends at and tips the balance to the other joint);
// per record, so that a chaotic record the twin cannot follow does not size the values alone; a
// one-joint device's held hip: 0. The chosen set's final values are refined with the weights of the
// extended twin's own misfit (step 7: feasible weighted least squares, one step).
//
// Candidates (MotionCandidates): every effect the plant carries, at every joint of the device:
// coulomb_friction, viscous_friction, inertia_error, gravity_error (X, Y), joint_stiffness (two
// parameters, k and k q0), passive_moment (a two-joint model with a human), backlash,
// series_compliance (as the compliance 1/k; at the knee with a human, at either joint without),
// sensor_offset, sensor_gain, sensor_delay (a reading as input), torque_ripple at the frequency the
// torque fit found (when it names one); not an effect the model given already carries at that joint,
// except the frictions and the inertia error, which the plant sums (a change on top of the model's
// own: a one-joint device's R and C are its knee's frictions).
// Box bounds: DESIGN.md's ranges (PhysicalScale of the records, diagnose_select.h).
//
// Method (Gauss-Newton with selection):
//  1. the torque fit (Diagnose with DiagnoseFit::kTorque, no simulation): starting values of the
//     effects it names, and what it would have named (Diagnosis::torque_named);
//  2. at the current theta (first: the model given, theta = 0) one rollout per parameter (forward
//     differences, each parameter's secant step MotionCandidateStep) gives the Jacobian J of qsim on
//     every scored sample; J's columns and the residual q - qsim(theta) + J theta form one ColumnBank
//     per record (rows weighted by w_rj), a linear model whose coefficients are the effects' values;
//  3. screening: each one-parameter candidate whose linear fit on top of the current set is
//     significant and lowers the BIC is refined alone on the exact plant (the secant method from the
//     current theta's rollout to the linear fit's value, one rollout per step, the set held;
//     kMotionScreenIterations rollouts at most) and its column replaced by the secant to that value (the current
//     set's own one-parameter effects: the secant from the set without them), so that the linear model
//     holds every candidate's exact single fit (a dead band or a strap is far from linear in its value);
//     then SelectEffects (diagnose_select.h: the torque fit's gates, shared) chooses the effects on that
//     model: BIC (effective sample size from the residual's autocorrelation length), held-out error at
//     the effect's joint (and, with several records, each whole record left out), materiality
//     (kMinTorqueShare of the measured angle's RMS about its mean), |t| > kMinT from J's covariance,
//     DESIGN.md's ranges, the simpler explanation preferred;
//  4. the chosen effects' values are refined on the exact plant: projected Levenberg-Marquardt inside
//     the box (stopped where the decrease it predicts is below 1e-5 of the cost), forward-difference
//     Jacobians, from the linear fit's values and from the torque fit's where it named the effect
//     (the lower error wins; where neither simulates, from the current values with the set's new
//     effects at 0; where that fails too, the last round's set stays); a dead band's value then
//     probed at +-1/4 and +-1/2 of its size (its cost is rough below that scale: a closure moves by
//     whole physics steps), the refinement restarted where a probe is lower (kMotionBandProbes rounds
//     at most);
//  5. steps 2-4 repeat at the refined theta until the chosen set repeats (at most kMotionOuterSteps);
//     a round that chose the last round's set again converged, and that set stays; where an earlier
//     round's set came back (a cycle) or no set repeated, the rounds' refined set of the lowest exact
//     fit-part BIC stays (a round linearized elsewhere may end on a worse set than an earlier one);
//     then exchanges (at most
//     kMotionExchanges): the swap of one chosen effect for one candidate, or for two below
//     max_effects (none of the new set in Conflicts), that
//     the last round's linear model ranks lowest in BIC, refined on the exact plant (step 4's
//     refinement from the set's values with the effect taken out and from the linear fit's), taken
//     where the exact fit-part BIC is lower (stepwise selection keeps an effect that entered early and
//     stands in for one that only pays once the others are in); then the friction's form: each named
//     viscous friction exchanged for a Coulomb one at its joint and the other way round, refined
//     from the value of the same power at the joint's RMS speed (c = b qd_rms) and the torque fit's,
//     taken where the exact fit-part BIC is lower; then backward elimination on the plant: each
//     chosen effect taken out and the rest refined from the set's values, the removal of the lowest
//     exact fit-part BIC taken where it is below the set's or where what the effect adds at its
//     joint is below the selection's materiality, repeated (these three on the last round's
//     set and, where an earlier round's set had the lower exact BIC, on that one too: the lower exact
//     BIC after them stays); then the torque fit's effects put to the plant:
//     each effect the torque fit names (step 1) that is a candidate and conflicts with no chosen one
//     (diagnose_select.h Conflicts), added at the torque
//     fit's value, is refined with the set where it lowers the held-out simulated error at its joint
//     by kMinHeldoutGain, and taken where the refined set's exact fit-part BIC is lower (the torque
//     residual has weighed it; the plant has to agree, not to find it again);
//  6. ranges and the exact held-out gate: a chosen effect whose refined value leaves its range
//     (Plausible; the selection checked the linear fit's value) is dropped and the rest refined again;
//     every chosen effect, taken out of the refined set, must raise the held-out
//     simulated error at its joint by at least kMinHeldoutGain of the set's, or (several records) the
//     error of the whole records left out, each simulated with the values of the set (with or without
//     the effect) one Gauss-Newton step from its refined ones on the other records' fit parts
//     (LeftOutThetas: a record's held-out end may lack the motion an effect shows in); one that passes
//     neither is dropped (the weakest first) and the rest refined again;
//  6b. never worse than the torque fit's twin: where the set replays the held-out parts above
//     kTorqueTwinTolerance times the torque fit's twin's RMS error at a joint, the torque fit's
//     effects refined, held at its values with the set's others added (those refined), added to the
//     set (all refined), or at its values: the lowest exact fit-part BIC within the tolerance; the
//     gate then read against the torque fit's twin; values held stay (step 7 refines the rest);
//  7. the weights set from the extended twin's misfit (MotionProblem::WeightBy) and the set's values
//     refined once more under them (step 4's refinement and band probes, from the current values);
//     95 % intervals from the final Jacobian: cov = s^2 (J'J)^-1, s^2 the fit part's residual variance
//     inflated by its autocorrelation length; beside them each value's spread across resamples of
//     the rows of the fit that produced it (motion_spread.cc: kSpreadBootstraps block bootstraps,
//     fifths left out; the motion objective's one Gauss-Newton step, or the torque fit's least squares
//     for a value step 6b held); every effect the torque fit names and the motion fit
//     does not is listed in Diagnosis::torque_only with the held-out simulated-error change it brings
//     (added to the set, and in the torque fit's twin);
//     the records left out (simulation.left_out) with the values LeftOutThetas gives at the final
//     Jacobian; beside them the torque fit's twin on the same rows (SimulationScores::torque_fit_*:
//     its effects on the held-out parts, its values fitted without each record on that record).
// Rollouts run in parallel on DiagnoseOptions::threads std::threads (one plant per rollout, built under
// a lock: MuJoCo's compiler is not reentrant), each stored by its index: the result does not depend on
// the thread count (the same bits).
//
// Diagnosis fields of a motion fit: effects (value, ci95), extended, selection, records (split: the
// simulated angle, rad), joints (the same pooled, rad), simulation (rigid vs extended, held-out and
// whole records left out, and the torque fit's twin on the same rows), noise (the records pooled:
// 1 / w_j, rad), tau_eff (rows), torque_named, torque_only, unexplained (the first record's held-out
// simulated angle, rad; MotionFit::FindUnexplained); cutoff and kin are the torque fit's (the
// report's header).
#pragma once
#include <array>
#include <cstdint>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_columns.h"
#include "diagnosis/diagnose_select.h"

namespace exotwin {

constexpr int kMotionOuterSteps = 4;     // linearize-select-refine rounds at most
constexpr int kMotionLmIterations = 8;   // Levenberg-Marquardt iterations per refinement at most
constexpr int kMotionScreenIterations = 4;  // rollouts of a candidate's screening fit at most
constexpr int kMotionBandProbes = 3;  // rounds of a dead band's probes after a refinement at most (step 4)
constexpr int kMotionExchanges = 3;   // effects exchanged at most (step 5)
// The motion fit's extended twin replays the held-out rows at most this times the RMS error of the
// torque fit's twin at each joint, else the torque fit's effects are put in its place (step 6b).
constexpr double kTorqueTwinTolerance = 1.05;
// Step 7's resamples of the fit rows: block bootstraps (blocks of a window's rows) and their seed.
constexpr int kSpreadBootstraps = 200;
constexpr uint64_t kSpreadSeed = 64;

// `exotwin diagnose --fit motion`: Diagnose (diagnose.h) with opt.fit == DiagnoseFit::kMotion. Throws
// InputError naming the record for a record the motion fit cannot use: neither a torque reading (a
// reading that is zero throughout at a joint of the device) nor cmd_* columns; a fit or held-out part
// shorter than one window of replay_horizon_s. SimulationError when the given twin diverges.
Diagnosis DiagnoseByMotion(const LegParams& params, const std::vector<const MeasuredData*>& records,
                           const DiagnoseOptions& opt);

struct FitFamily;  // diagnosis/fit_families.h

// The simulated-motion problem of some records: the candidates as columns, rollouts, Jacobians.
class MotionProblem {
 public:
  // `torque_named`: the torque fit's effects (a torque_ripple among them adds its ripple candidate).
  MotionProblem(const LegParams& params, const std::vector<const MeasuredData*>& records,
                const DiagnoseOptions& opt, const std::vector<DiagnosedEffect>& torque_named = {});
  ~MotionProblem();

  // The candidates (Candidate::cols index the parameters) and each parameter's box and step.
  const std::vector<Candidate>& candidates() const { return candidates_; }
  int parameters() const { return static_cast<int>(lo_.size()); }
  double lower(int k) const { return lo_[k]; }
  double upper(int k) const { return hi_[k]; }
  double step(int k) const { return step_[k]; }
  const std::string& kind(int k) const { return kind_[static_cast<size_t>(k)]; }  // a family's name, or "offset"
  double ripple_f(int k) const { return ripple_f_[static_cast<size_t>(k)]; }  // a frequency it carries (cycles/rad)
  // Index of the candidate (name, joint "hip"/"knee", axis for gravity_error), -1 if not a candidate.
  int CandidateIndex(const std::string& name, const std::string& joint, const std::string& axis = "") const;
  // Why effect e (as the torque fit names it) is no candidate, "" when it is one: the plant cannot
  // carry it, the model given already carries one there, no torque reading to correct, ...
  std::string WhyNoCandidate(const Effect& e) const;
  const PhysicalScale& scale() const { return scale_; }
  double qd_rms(int j) const { return qd_rms_[j]; }  // rad/s, RMS of the measured joint speed, every record
  double weight(int j) const { return w_[j]; }  // pooled over the records (the noise reported)
  // The weight of record r's rows at joint j: 1 / the misfit level there (the constructor's: the lower
  // RMS simulated-angle error of the model given and of the torque fit's twin; WeightBy's).
  double weight(size_t r, int j) const { return rw_[r][static_cast<size_t>(j)]; }
  size_t records() const { return rec_.size(); }
  // The input between samples (ReplaySeries::hold): the one under which the model given follows the
  // records' fit parts closer.
  bool hold() const { return hold_; }

  // The effects (Effect list appended to the model's) that theta stands for.
  std::vector<Effect> EffectsOf(const Eigen::VectorXd& theta) const;

  // Simulated angles on every record's scored rows (per record a vector of 2 m: hip rows then knee
  // rows, each the fit part's samples first; NaN on the part not simulated); ok false when the plant
  // cannot carry theta's effects or diverges.
  enum class Part { kFit, kHeldOut, kBoth };
  struct Rollout {
    bool ok = false;
    std::vector<Eigen::VectorXd> q;
  };
  Rollout Simulate(const Eigen::VectorXd& theta, Part part) const;
  // Record `record` alone, both parts (the other records' rows NaN).
  Rollout SimulateRecord(const Eigen::VectorXd& theta, size_t record) const;
  // Many rollouts in parallel (the result of k at [k]).
  std::vector<Rollout> SimulateAll(const std::vector<Eigen::VectorXd>& thetas, Part part) const;
  // thetas[r] on record r alone, in parallel (SimulateRecord).
  std::vector<Rollout> SimulateEachRecord(const std::vector<Eigen::VectorXd>& thetas) const;

  // Forward-difference Jacobian of the simulated angles (rad per unit of parameter; rows as Simulate's,
  // records stacked) with respect to parameters `cols` at theta, whose rollout is `at`; a column is
  // taken backwards where the forward step leaves the box, and is zero where neither rollout runs.
  Eigen::MatrixXd Jacobian(const Eigen::VectorXd& theta, const Rollout& at, const std::vector<int>& cols,
                           Part part) const;

  // Per record: scored sample indices, fit-part rows (the first fit_rows of them), measured angles.
  const std::vector<size_t>& rows(size_t r) const;
  size_t fit_rows(size_t r) const;
  size_t windows(size_t r, Part part) const;  // Replay's windows of record r on that part (both: the sum)
  const Eigen::VectorXd& measured(size_t r) const;  // measured angle on the rows (rad), Simulate's layout
  // Weighted SSE of a rollout per joint, on the fit part or the held-out part.
  void Sse(const Rollout& ro, Part part, double sse[2]) const;
  // Unweighted SSE of a rollout per joint on part `part` of record r (rad^2), and that part's rows.
  void RecordSse(const Rollout& ro, size_t r, Part part, double sse[2], double* count) const;
  // The weights from the misfit of rollout `ro` (its fit parts simulated): w_rj = 1 / its RMS
  // simulated-angle error on record r's fit part at joint j, the pooled w_j likewise (motion_fit.h
  // "Output weights", step 7); a one-joint device's hip keeps 0.
  void WeightBy(const Rollout& ro);
  // The simulation done so far, in replays of the records: every Simulate call counts the share of the
  // records' scored rows it simulates (a fit part alone: its share; both parts: 1).
  double ReplaysSimulated() const;

 private:
  struct Record;
  Rollout Run(const Eigen::VectorXd& theta, Part part, int only) const;  // only >= 0: that record alone
  // The candidates (candidates_) and their parameters (kind_, joint_, lo_, hi_, step_, ripple_f_) of
  // the records' kinematics `kins` (motion_fit.h "Candidates"; sets qd_rms_), motion_candidates.cc.
  void AddCandidates(const std::vector<Kinematics>& kins, const std::vector<DiagnosedEffect>& torque_named);
  // rw_ and w_ = 1 / the RMS of per-record fit-part SSEs `sse` and of the pooled `pooled` (rad^2);
  // a one-joint device's hip: 0.
  void SetWeights(const std::vector<std::array<double, 2>>& sse, const double pooled[2]);
  LegParams params_;
  DiagnoseOptions opt_;
  std::vector<std::unique_ptr<Record>> rec_;
  std::vector<Candidate> candidates_;
  std::vector<double> lo_, hi_, step_;
  std::vector<std::string> kind_;  // per parameter: what it is (a family's name, or "offset")
  std::vector<int> joint_;         // per parameter
  std::vector<double> ripple_f_;   // per parameter (torque_ripple)
  std::vector<const FitFamily*> owner_;  // per parameter: the family whose effect it stands for (EffectsOf)
  PhysicalScale scale_;
  double w_[2] = {1, 1};
  double qd_rms_[2] = {1, 1};
  std::vector<std::array<double, 2>> rw_;  // per record
  bool reading_input_ = true;      // every record driven by its torque reading
  bool hold_ = false;              // ReplaySeries::hold of every record
  double fit_share_ = 1;            // the fit parts' share of the scored rows
  mutable std::atomic<long> rollouts_[3] = {{0}, {0}, {0}};  // Simulate calls per Part
  mutable std::atomic<long> record_rows_{0};  // scored rows simulated by SimulateRecord
  double all_rows_ = 1;                       // scored rows of every record
};

}  // namespace exotwin
