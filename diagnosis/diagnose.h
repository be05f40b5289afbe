// `exotwin diagnose` (DESIGN.md): where the twin and the measured data disagree, which effects of
// the DESIGN list explain it (with values and 95 % intervals), the extended model, and the held-out
// gain; on one record or on several records of one device.
//
// Method (diagnose.cc, diagnose_select.h):
//  1. derivatives: the cutoff of the zero-phase derivative filter is chosen from the data
//     (derivative_cutoff.h) unless given; the measured torque is filtered alike (parallel
//     filtering), so the filter's lag and attenuation, and the noise that differentiation injects
//     into the prediction above the cutoff, never show as a discrepancy.
//  2. residual r = filtered measured tau_S - twin tau_S, per joint; white-noise level per joint from
//     the first differences of r; rows weighted by 1/noise.
//  3. candidates: every effect per joint, each as columns of a linear model of r (first order in the
//     effect: sign(qd), qd, qdd, g sin/cos, [q, 1], (b/2) s(tau) dtau/dq, dtau_C/dq tau_C,
//     sin/cos(2 pi f q), 1, tau_S, -dtau_S/dt, EMG envelopes). The ripple frequency is found by grid
//     + golden search; delay, backlash and strap stiffness are refined by golden search on the exact
//     model after selection.
//  4. the effects are selected jointly (forward selection with backward elimination, up to
//     max_effects, diagnose_select.h), fitted on the first 70 % of every record; each must be
//     significant, physically plausible (DESIGN.md's ranges), and pay on held-out data (the last
//     30 % of every record and, with several records, every whole record left out in turn).
//  5. the extended twin (predict with the effects) runs on the held-out parts: rmse_after; with
//     several records, each whole record is also predicted by the effects fitted on the others.
//  6b. forward simulation (replay.h): the rigid twin (the model given) and the extended twin, their
//     effects in the MuJoCo plant, driven by the measured torque and restarted from the measured
//     state every DiagnoseOptions::replay_horizon_s, on the held-out part of every record and, with
//     several records, on every whole record with the effects fitted on the others: the gain in
//     simulated angle (Diagnosis::simulation). Skipped, with the reason, when a twin holds an effect
//     the plant cannot carry (sim/plant_effects.h).
//  6. structure left in the held-out residual (low-passed rms well above the noise) is reported as
//     unexplained with its dominant frequency and its correlation with angle, velocity, accel, time.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "diagnosis/completeness.h"
#include "diagnosis/derivative_cutoff.h"
#include "diagnosis/replay.h"
#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// A set of candidates that can stand in a named effect's place: with it fitted (and the other named
// effects), the effect would add almost nothing (its column lies nearly in the set's span), so the
// data cannot tell them apart (e.g. a sensor gain and an inertia + gravity correction of a one-joint
// device, whose columns I qdd + mgl sin q are the twin's torque itself).
struct EffectAlias {
  std::vector<Effect> effects;  // the candidates at the values fitted in its place
  double reach_pct = 0;         // the set's drop of the fit rows' error, % of the named effect's
  double left_pct = 0;          // what the named effect would still add to the set, % of its drop
  bool plausible = true;        // every value inside its physical range
};

struct DiagnosedEffect {
  Effect effect;
  double ci_lo = 0, ci_hi = 0;  // 95 % interval of effect.value
  double explained_pct = 0;     // % of the held-out residual sum of squares this effect removes
  // Single candidates, and pairs of which neither alone qualifies, with left_pct <= 100 kAliasLeft
  // (diagnose.cc FindAliases); those in range first, singles before pairs, then the most reaching;
  // at most kMaxAliases.
  std::vector<EffectAlias> aliases;
  // The motion fit: the value's spread across resamples of the fit rows (motion_fit.h step 7):
  // spread_sd the standard deviation over kSpreadBootstraps block bootstraps, spread_lo / spread_hi
  // the least and largest value with each fifth of the fit rows left out in turn. NaN: not resampled.
  double spread_sd = NAN, spread_lo = NAN, spread_hi = NAN;
};

constexpr double kAliasLeft = 0.01;  // an alias leaves the named effect at most 1 % of its drop of the fit error
constexpr size_t kMaxAliases = 6;

struct UnexplainedStructure {
  std::string joint;
  double rms = 0;                // N m, low-passed (5 Hz) held-out residual after the extension
                                 // (the motion fit: rad, the simulated angle's)
  double dominant_hz = 0;        // peak of the residual spectrum
  double corr_q = 0, corr_qd = 0, corr_qdd = 0, corr_t = 0;  // Pearson correlation with r
  std::string hint;              // words: what it looks like
};

struct CandidateScore {
  std::string label;  // e.g. "coulomb_friction(knee)" or "a + b"
  double delta_bic = 0, heldout_gain_pct = 0;
  bool selected = false;
};

struct JointScore {
  double rmse_before = 0, rmse_after = 0, gain_pct = 0;  // on the held-out part, N m (simulation: rad)
};

// Scores of one record.
struct RecordScore {
  std::string source;
  size_t samples = 0;
  JointScore split[2];     // its last 30 %, effects fitted on the first 70 % of every record
  JointScore left_out[2];  // the whole record, effects fitted on the other records (>= 2 records)
  // The whole record (its fit rows), every candidate column at once fitted on this record alone, in
  // sample: the least error any combination of the candidate effects, in their columns' linear form
  // and at any values, reaches on it. Bounds the left-out gain (effects fitted on the other records).
  JointScore ceiling[2];
  // The ceiling under the null hypothesis that the residual is no function of the motion: the same
  // fit against this record's residual shifted circularly in time (its spectrum kept; five shifts,
  // the after-error averaged). A ceiling near it holds nothing the effects could carry to other
  // records. What a shift reproduces is no test: a constant (an offset is no function of the motion
  // either) or a motion periodic over the shift.
  JointScore ceiling_null[2];
  std::vector<Effect> left_out_effects;  // the model's effects and those (>= 2 records)
  // Simulated angle, rigid (before) vs extended (after) twin, rad: the held-out part, and the whole
  // record with left_out_effects; windows 0 where the part is shorter than the horizon.
  JointScore sim_split[2], sim_left_out[2];
  size_t sim_split_windows = 0, sim_left_out_windows = 0;
};

// The forward simulation of the twins (step 6b).
struct SimulationScores {
  bool done = false;
  std::string note;          // why not done, or what was done
  double horizon_s = 0.5;
  double cutoff_hz = 10;     // the restart state's filter
  JointScore split[2];       // pooled over the held-out parts, rad
  JointScore left_out[2];    // pooled over the whole records left out, rad
  // A motion fit: the torque fit's extended twin (its effects, and per record left out the torque
  // fit's values without that record) simulated on the same rows as split and left_out (rmse_before
  // the model given, rmse_after the torque fit's twin); effects the plant cannot carry are left out
  // of it and listed in torque_fit_not_carried.
  bool torque_fit_done = false;
  JointScore torque_fit_split[2], torque_fit_left_out[2];
  std::vector<std::string> torque_fit_not_carried;
  // A motion fit whose extended twin still replays the held-out rows worse than the torque fit's twin
  // (above kTorqueTwinTolerance times its RMS error at a joint, motion_fit.h): why, in words; else empty.
  std::string torque_fit_why;
  // First record's held-out part: time, measured angle, rigid and extended twin's simulated angle
  // (NaN between windows).
  std::vector<double> t, measured[2], rigid[2], extended[2];
};

// Which fit sizes and chooses the effects: the torque residual (inverse dynamics, this header's method)
// or the simulated motion (the forward plant on the records, diagnosis/motion_fit.h).
enum class DiagnoseFit { kTorque, kMotion };
// "torque" / "motion" (diagnosis.json's `fit`, the --fit option's words).
const char* DiagnoseFitName(DiagnoseFit fit);
// The fit a --fit option names; InputError "<where>: '<text>', expected torque or motion" otherwise.
DiagnoseFit ParseDiagnoseFit(const std::string& text, const std::string& where);
// The columns a diagnosis reads besides t, q_*, tau_* (formats/measured_data.h MeasuredColumns): the
// recorded qd_*, qdd_* and emg_* columns, and with the motion fit cmd_* (the input where a joint's
// reading is zero). A run's ref_* and state, and the torque fit's cmd_*, are not read.
bool DiagnoseReadsColumn(const std::string& name, DiagnoseFit fit);

// The motion fit: an effect the torque fit names that the motion fit does not (it does not lower the
// held-out simulated error enough, or is not carried by the plant).
struct TorqueOnlyEffect {
  Effect effect;                           // as the torque fit sized it
  bool simulated = false;                  // false: no rollout with it, for the reason in `why`
  std::string why;                         // when not simulated: the forward plant cannot carry it
                                           // (muscle_activity), the model given already carries one
                                           // (no candidate), no sensor to correct, or its rollout failed
  // The held-out simulated-angle RMS error's change per joint (unweighted, the final comparison's
  // measure), % (< 0: lower): added at that value to the motion fit's effects; and its share in the
  // torque fit's twin, that twin against the twin without it (NaN: not simulated).
  double heldout_change_pct[2] = {0, 0};
  double in_torque_twin_pct[2] = {NAN, NAN};
};

// A model's black-box ceiling at one joint (DESIGN.md "Terms beyond the table": `ceiling`), on the
// held-out rows (a subsample, the same rows for both): named_pct = 100 (1 - SSE(model) / SSE(given)),
// the share of the model given's held-out residual sum of squares the model removes; black_box_pct
// the same for the model plus a black box (black_box.h) trained on the model's residual on the fit
// rows, with the states q, qd, qdd, tau_R of both joints and their values 50 and 100 ms back as inputs.
struct JointCeiling {
  bool done = false;  // false: no rows, or the model given leaves no residual
  double named_pct = 0, black_box_pct = 0;
  double given_rms = 0;  // the model given's held-out residual RMS on those rows, N m
  size_t train_rows = 0, heldout_rows = 0;
};

// One model's residual tests and ceiling at both joints (a one-joint device: the hip's left unassessed).
struct ModelAssessment {
  JointCompleteness completeness[2];
  JointCeiling ceiling[2];
};

// A named term's component-plus-residual plot (the report's "residual against the term's signals"):
// on the first record's fit rows (at most kTermPlotPoints of them, evenly strided), the final model's
// residual plus the term's own fitted torque (partial), against the term's shape (its torque per unit
// value, filtered as the residual: partial = value * shape where the term is right) and against each
// signal the term reads (unfiltered). N m, the signals in their grammar units.
struct TermPlot {
  std::string joint, expr;
  double value = 0;
  std::vector<double> shape, partial;
  std::vector<std::pair<std::string, std::vector<double>>> signals;
};
constexpr size_t kTermPlotPoints = 1500;

struct Diagnosis {
  DiagnoseFit fit = DiagnoseFit::kTorque;
  std::vector<DiagnosedEffect> effects;
  std::vector<UnexplainedStructure> unexplained;
  JointScore joints[2];
  double holdout_fraction = 0.3;
  std::string method;
  LegParams extended;                   // params + effects
  std::vector<CandidateScore> scores;   // singles (best first) and the best pairs, for the report
  std::vector<std::string> collinear;   // nearly collinear candidate pairs on this record, in words
  std::vector<std::string> selection;   // the selection's steps, in words
  std::vector<std::string> term_search; // the search for terms beyond the table, in words (term_search.h)
  std::vector<TermPlot> term_plots;     // one per named term (term_search.h)
  std::vector<std::string> implausible; // candidates that fit alone but fall outside their range
  // Candidates these records cannot identify: fitted alone, even a value at the edge of their physical
  // range would not be significant (|t| < kMinT), e.g. an inertia on a slow, hand-guided record.
  std::vector<std::string> not_identifiable;
  CutoffChoice cutoff;                  // derivative (and parallel torque) filter, and why
  std::vector<RecordScore> records;     // per record (first: the plotted one)
  bool leave_one_out = false;           // several records: whole records left out in turn
  JointScore left_out[2];               // pooled over the left-out records
  double noise[2] = {0, 0};             // white noise of the residual, N m
  double tau_eff = 1;                   // residual autocorrelation length (fit rows)
  SimulationScores simulation;          // step 6b
  // Series for plots (first record): measured (filtered alike), twin before, extended twin after
  // (held-out part); split index.
  Kinematics kin;
  std::vector<double> measured[2], before[2], after[2];
  size_t split = 0;
  // The motion fit only: what the torque fit named (its values), and those the motion fit does not.
  std::vector<DiagnosedEffect> torque_named;
  std::vector<TorqueOnlyEffect> torque_only;
  // The table's best model (the extended twin of the table's effects, before the search for terms) and
  // the final model (D.extended, after the search; the table's where no term was admitted, and in the
  // motion fit, which searches none): their held-out residual tests
  // (completeness.h) and ceiling. Both fits assess the torque residual of their extended twin on the
  // held-out part of every record (the last holdout_fraction of its time), filtered as the torque
  // fit's (parallel filtering at its cutoff).
  ModelAssessment table_model, final_model;
};

struct DiagnoseOptions {
  double holdout_fraction = 0.3;
  size_t max_fit_rows = 60000;  // per joint; longer records are strided
  int max_effects = 6;
  double cutoff_hz = 0;          // derivative and parallel torque filter, Hz; 0 = chosen from the data
  std::string mjcf;              // MJCF instead of the shipped model
  bool simulate = true;          // step 6b (false: the torque analysis alone)
  bool assess = true;            // stage 5c, the residual tests and ceilings (and 6c; false: none, `completeness` and `ceiling` not assessed)
  bool search_terms = true;      // stage 5c, the search for terms beyond the table (the motion fit's own torque fit: false)
  double replay_horizon_s = 0.5; // step 6b: restart interval of the forward simulation, s
  double replay_cutoff_hz = kReplayCutoffHz;  // step 6b: filter of the restart state
  DiagnoseFit fit = DiagnoseFit::kTorque;     // kMotion: diagnosis/motion_fit.h (quiet windows of
                                              // replay_horizon_s, restart state at motion_cutoff_hz)
  double motion_cutoff_hz = 40;  // the motion fit's restart-state filter, at most a tenth of a record's rate
  int threads = 0;  // threads for the replays (the motion fit's rollouts; the torque fit's rigid and
                    // extended twins side by side, step 6b); 0: every core. The result does not depend on it.
};

// The threads DiagnoseOptions::threads asks for: itself when > 0, else the machine's cores (at least 1).
int DiagnoseThreads(const DiagnoseOptions& opt);

// Runs the discrepancy analysis. `params` is the twin to confront, `records` the measured records of
// one device (each >= 200 samples, the same columns, comparable sample rates). Throws InputError on
// unusable input (e.g. too short, records of different devices), SimulationError if the twin cannot
// be evaluated.
Diagnosis Diagnose(const LegParams& params, const std::vector<const MeasuredData*>& records,
                   const DiagnoseOptions& opt = {});
// The same, consuming the records (left empty): their columns are moved into the analysis instead
// of copied, for long records (`exotwin diagnose`). The same result, bit for bit.
Diagnosis Diagnose(const LegParams& params, std::vector<MeasuredData>&& records, const DiagnoseOptions& opt = {});
inline Diagnosis Diagnose(const LegParams& params, const MeasuredData& data, const DiagnoseOptions& opt = {}) {
  return Diagnose(params, std::vector<const MeasuredData*>{&data}, opt);
}

// diagnosis.json text (DESIGN.md format plus `signature` fields in unexplained).
std::string DiagnosisJson(const Diagnosis& d);

// An alias in words, e.g. "inertia_error (knee) = 0.0135 kg m^2 + gravity_error.X (knee) = 0.0274 kg m
// (reaches 100 % of its fit)", " [outside its range]" appended when implausible.
std::string AliasText(const EffectAlias& a);

// Writes DIR/diagnosis.json, DIR/extended.yaml and DIR/report.html (creates DIR). measured_path
// names the record(s), for the report.
void WriteDiagnosis(const Diagnosis& d, const std::string& dir, const std::string& params_path,
                    const std::string& measured_path);

}  // namespace exotwin
