// The torque fit's internal parts shared by its files (diagnose.cc, diagnose_ceiling.cc,
// diagnose_torque_effects.cc).
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_columns.h"
#include "diagnosis/diagnose_select.h"
#include "formats/measured_data.h"

namespace exotwin {

// Held-out scores from the sums of squares before / after over `count` samples.
JointScore ScoreOf(double sse_before, double sse_after, double count);

// Stage 3d: every record's ceiling (RecordScore::ceiling): all candidate columns at once fitted on
// that record's bank alone, each effect's value of the sign its range allows (coulomb, viscous,
// backlash, series_compliance's 1/k, sensor_delay, joint_stiffness >= 0; the others free: a
// relaxation of DESIGN.md's ranges, so the ceiling bounds any in-range combination), scored on its
// fit rows against the residual of the model given (weights undone; a joint of weight 0, a
// one-joint device's held hip, scores 0). Also its null level (RecordScore::ceiling_null): the same
// fit against the residual shifted circularly in time by kNullShifts of the record's rows (every
// joint alike), the after-error's sum of squares averaged over the shifts: a circular-shift
// permutation test of "the residual is no function of the motion", its spectrum kept.
struct CeilingScores {
  JointScore ceiling[2], null[2];
};
std::vector<CeilingScores> Ceilings(const std::vector<ColumnBank>& banks, const double w[2]);

namespace torque_fit {

// The rigid twin's actuator torque (HJ15 eq. 5-7 + P(q), model/leg_dynamics.h ActuatorTorque) on
// every sample of kin, into tau_R[0..1] (resized), on `threads` threads.
void RigidTorque(const LegParams& params, const Kinematics& kin, int threads, std::vector<double> tau_R[2]);

// One record prepared at the chosen cutoff: trimmed kinematics, the measured torque filtered alike,
// the twin's prediction and the residual.
struct Rec {
  std::string source;  // the record's name, for messages
  size_t samples = 0;  // the record's samples (before the trim)
  Kinematics kin;
  std::vector<double> taken[2];         // the record's tau_hip, tau_knee when Diagnose took it over
  const double* raw[2] = {nullptr, nullptr};  // measured tau_S: the record's, from kin.t's first sample
  std::vector<double> meas[2];          // measured tau_S, filtered as the angles (for plots; released by stage 6)
  double hz = 0;                        // the parallel low-pass (0: none)
  // The twin: the rigid actuator torque (after stage 2 only on [0, RefineRows)) and the reading
  // with the model's effects (released by stage 6).
  std::vector<double> tau_R[2], tau_S[2];
  std::vector<double> resid[2];         // Residuals(); released once the candidate columns took their rows
  size_t split = 0;
  std::optional<TimeBaseLowPass> low;   // the low-pass at hz on kin.t (hz > 0)
  size_t n() const { return kin.t.size(); }
  // The residual's low-pass (parallel filtering: measured and predicted torque filtered alike) of x,
  // whose samples are those of kin.t from `from` on.
  std::vector<double> Filter(std::vector<double> x, size_t from = 0) const {
    if (!(hz > 0)) return x;
    if (from == 0 && x.size() == kin.t.size()) return (*low)(std::move(x));
    const std::vector<double> t(kin.t.begin() + from, kin.t.begin() + from + x.size());
    return LowPassOnTimeBase(t, x, hz, source);
  }
  // Filter of x[0] and x[1] (one length) together, in place: interleaved, each the same bits as Filter.
  void FilterBoth(std::vector<double> x[2], size_t from = 0) const {
    if (!(hz > 0)) return;
    std::vector<double>* p[2] = {&x[0], &x[1]};
    if (from == 0 && x[0].size() == kin.t.size()) return low->Apply(p, 2);
    const std::vector<double> t(kin.t.begin() + from, kin.t.begin() + from + x[0].size());
    TimeBaseLowPass(t, hz, source).Apply(p, 2);
  }
  // The filtered residuals of both joints, measured - twin (raw - tau_S), on kin.t's samples: the same
  // bits wherever they are computed.
  void Residuals(std::vector<double> e[2]) const {
    for (int j = 0; j < 2; ++j) {
      e[j].resize(n());
      for (size_t i = 0; i < e[j].size(); ++i) e[j][i] = raw[j][i] - tau_S[j][i];
    }
    FilterBoth(e);
  }
  ColumnFilter FilterFn() const {
    if (!(hz > 0)) return {};
    return [this](std::vector<double>* const* xs, size_t count) { low->Apply(xs, count); };
  }
  // The measured tau_S of joint j on kin.t's samples (raw[j]'s n values), for the last user of raw:
  // the column taken over, cut in place, else a copy. raw[j] is left null.
  std::vector<double> TakeRaw(int j) {
    std::vector<double> v;
    if (taken[j].empty()) {
      v.assign(raw[j], raw[j] + n());
    } else {
      const size_t off = static_cast<size_t>(raw[j] - taken[j].data());
      v = std::move(taken[j]);
      v.erase(v.begin() + static_cast<long>(off + n()), v.end());
      v.erase(v.begin(), v.begin() + static_cast<long>(off));
    }
    raw[j] = nullptr;
    return v;
  }
};

// Stage 3b: every column of a family with a secant (FitFamily::secant_column: the delay's (tau_S(t - d)
// - tau_S(t)) / d) replaced by it at the value d the single fit gives the column (pooled over
// records), twice, so the second-order term is not left for another column (the gain's).
void UseSecantColumns(const std::vector<Rec>& recs, const double w[2], std::vector<ColumnBank>* banks_io);

// The largest magnitude DESIGN.md's physical range allows a one-parameter candidate (0: unbounded or
// several parameters).
double RangeEdge(const Candidate& c, const PhysicalScale& s);

// The samples [0, RefineRows) of a record on which stage 5 refines (of R records).
size_t RefineRows(const Rec& rc, size_t R);

// Stage 5: the extension D->extended = params + the chosen effects (D->effects); delay, backlash
// and strap stiffness refined by golden search on the exact model (fit rows); each effect's share of
// the held-out residual (leave-one-effect-out). Returns each effect's refined / linear value ratio.
std::vector<double> ExtendAndRefine(const LegParams& params, const std::vector<Rec>& recs, const double w[2],
                                    const ColumnBank& bank, const Grams& g, const Fit& f0,
                                    const std::vector<int>& chosen, const Fit& chosen_fit, Diagnosis* D);

// Stage 2 (diagnose.cc): one record at the chosen cutoff into *rc: kinematics trimmed of the zero-phase
// filters' transients, measured torque filtered alike, the held-out split at 1 - holdout_fraction of
// its time, the twin's torque (HJ15 eq. 5-7 + P + the model's effects) and the filtered residual.
// With `owned` (the record itself, which Diagnose may consume) its columns are moved, not copied: the
// record is left empty.
void PrepareRecord(const LegParams& params, const MeasuredData& data, MeasuredData* owned,
                   const CutoffChoice& cutoff, double holdout_fraction, int threads, Rec* out);

// Stages 5c and 6c (diagnose_completeness.cc): `model`'s assessment on the records against the model
// given (`given`, whose rigid twin gives tau_R): the residual tests (completeness.h) of its filtered torque
// residual on every record's held-out rows [split, n), decimated by CompletenessStep at the record's
// cutoff, one segment per record, the material floor kMinTorqueShare of the measured torque's RMS on
// those rows (the selection's); and its ceiling (JointCeiling), the black box trained on the model's
// residual at most 12000 fit rows (the last quarter of every record's fit rows validating) and scored
// on at most 8000 held-out rows. Both twins by the closed form (HJ15 + ApplyEffects, as stage 2),
// which every effect (and term) ApplyEffects knows reaches. Needs each record's kin (with EMG for
// muscle_activity) and raw. Called for the table's best model and, where the search for terms
// admitted one, for the final model.
ModelAssessment AssessModel(const LegParams& given, const LegParams& model, const std::vector<Rec>& recs,
                            const DiagnoseOptions& opt);
// The black box's rows of AssessModel: its inputs on the fit rows (with the validation rows) and on
// the held-out rows, the model given's residual on the held-out rows, and the residual of every model
// tested on them (model k: columns 2k (hip) and 2k + 1 (knee) of fit_y and held_y).
struct CeilingRows {
  Eigen::MatrixXd fit_x, held_x, held_given, fit_y, held_y;
  std::vector<bool> validation;
  int models = 0;
  bool one_joint = false;
};
// AssessModel in two parts, so that the ceilings of several models on the same rows are one black
// box fit (the table's best model's and the final one's: the inputs are the same, only the
// residual differs). TestModel: the residual tests; the model's residual appended to *rows (the
// inputs filled on the first call); with `on_fit_rows`, the residual tests on every record's fit rows
// [0, split) too (the material floor from those rows): what decides the search for terms beyond the
// table, so that an effect that fades before the held-out end (a drive warming up) is seen where it
// acts. FitCeilings: the ceiling of model k of *rows into out[k] (one black box, its output columns
// fitted independently: the same as one fit per model).
ModelAssessment TestModel(const LegParams& given, const LegParams& model, const std::vector<Rec>& recs,
                          const DiagnoseOptions& opt, CeilingRows* rows,
                          std::array<JointCompleteness, 2>* on_fit_rows);
void FitCeilings(const CeilingRows& rows, const std::vector<ModelAssessment*>& out, const DiagnoseOptions& opt);
// Whether the ceiling `c` says the named model leaves structure at a joint by the gates a table
// effect passes (diagnose_select.h): the black box trained on its residual lowers its held-out sum of
// squares by at least kMinHeldoutGain, and the part it removes is material (its RMS at least `floor`,
// the completeness tests' material floor). Decides the search beside the residual tests: it needs no
// minimum of decimated rows (a short held-out part, a low cutoff) and sees any function of the states,
// tau_R and their short history.
bool CeilingLeavesStructure(const JointCeiling& c, double floor);
// The share of the named model's held-out sum of squares the black box removes (fraction; 0 when not done).
double BlackBoxShareOfResidual(const JointCeiling& c);
// The same on the records themselves (the motion fit's): each prepared as stage 2 does at `cutoff`
// (the torque fit's) with the model given, then AssessModel.
ModelAssessment AssessModelOnRecords(const LegParams& given, const LegParams& model,
                                     const std::vector<const MeasuredData*>& records, const CutoffChoice& cutoff,
                                     const DiagnoseOptions& opt);

}  // namespace torque_fit
}  // namespace exotwin
