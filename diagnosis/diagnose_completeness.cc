// Stages 5c (the table's best model) and 6c (the final one) of both fits (diagnose.h): a model's
// held-out residual tests (completeness.h) and its black-box ceiling (black_box.h, JointCeiling).
#include <algorithm>
#include <array>
#include <cmath>

#include "diagnosis/black_box.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/effects.h"

namespace exotwin {
namespace torque_fit {

namespace {

// The black box's rows: at most this many fit rows and held-out rows over the records (strided).
constexpr size_t kBlackBoxFitRows = 12000, kBlackBoxHeldOutRows = 8000;
constexpr double kHistoryS = 0.05;          // the inputs' history: 50 and 100 ms back
constexpr double kValidationShare = 0.25;   // the last quarter of every record's fit rows chooses the ridge

// One record's rigid actuator torque (HJ15 closed form) and the residuals of the model given and of
// `model`, filtered as the torque fit's (Rec::FilterBoth), on every row.
struct RecordResiduals {
  std::vector<double> tau_R[2], given[2], model[2];
};

RecordResiduals ResidualsOf(const LegParams& given, const LegParams& model, const Rec& rc, int threads) {
  RecordResiduals out;
  const Kinematics& kin = rc.kin;
  const size_t n = rc.n();
  RigidTorque(given, kin, threads, out.tau_R);
  auto Residual = [&](const LegParams& p, std::vector<double> e[2]) {
    std::vector<double> tau[2] = {out.tau_R[0], out.tau_R[1]};
    ApplyEffects(p, kin, tau, e);  // e: the reading tau_S
    for (int j = 0; j < 2; ++j)
      for (size_t i = 0; i < n; ++i) e[j][i] = rc.raw[j][i] - e[j][i];
    rc.FilterBoth(e);
  };
  Residual(given, out.given);
  Residual(model, out.model);
  return out;
}

// Joint j's held-out rows [split, n) of a record every `step` rows, as a test segment.
// Joint j's rows [a, b) of a record every `step` rows, as a test segment.
ResidualSegment SegmentOf(const Rec& rc, const RecordResiduals& res, int j, size_t step, size_t a, size_t b) {
  ResidualSegment s;
  const Kinematics& kin = rc.kin;
  for (size_t i = a; i < b; i += step) {
    s.e.push_back(res.model[j][i]);
    s.q.push_back(kin.q[j][i]), s.qd.push_back(kin.qd[j][i]), s.qdd.push_back(kin.qdd[j][i]);
    s.tau_R.push_back(res.tau_R[j][i]);
    s.q_other.push_back(kin.q[1 - j][i]), s.qd_other.push_back(kin.qd[1 - j][i]);
    s.t.push_back(kin.t[i] - kin.t.front());
  }
  return s;
}

// Joint j's held-out rows [split, n).
ResidualSegment SegmentOf(const Rec& rc, const RecordResiduals& res, int j, size_t step) {
  return SegmentOf(rc, res, j, step, rc.split, rc.n());
}

// The black box's inputs at row i (i >= 2 h): q, qd, qdd, tau_R of both joints, and q, qd, tau_R of
// both joints h and 2 h rows back.
constexpr int kInputs = 8 + 12;
void InputsAt(const Rec& rc, const RecordResiduals& res, size_t i, size_t h, double* x) {
  const Kinematics& kin = rc.kin;
  int c = 0;
  for (int j = 0; j < 2; ++j) x[c++] = kin.q[j][i], x[c++] = kin.qd[j][i], x[c++] = kin.qdd[j][i], x[c++] = res.tau_R[j][i];
  for (size_t back : {h, 2 * h})
    for (int j = 0; j < 2; ++j)
      x[c++] = kin.q[j][i - back], x[c++] = kin.qd[j][i - back], x[c++] = res.tau_R[j][i - back];
}

}  // namespace

ModelAssessment AssessModel(const LegParams& given, const LegParams& model, const std::vector<Rec>& recs,
                            const DiagnoseOptions& opt) {
  ModelAssessment out;
  const int j0 = given.one_joint ? 1 : 0;  // a one-joint device: the held hip is no data
  std::vector<ResidualSegment> segs[2];
  size_t step0 = 0;
  // The black box's rows: the strides that keep them within the limits.
  size_t fit_total = 0, held_total = 0;
  for (const Rec& rc : recs) fit_total += rc.split, held_total += rc.n() - rc.split;
  const size_t fit_stride = std::max<size_t>(1, (fit_total + kBlackBoxFitRows - 1) / kBlackBoxFitRows);
  const size_t held_stride = std::max<size_t>(1, (held_total + kBlackBoxHeldOutRows - 1) / kBlackBoxHeldOutRows);
  std::vector<std::array<double, kInputs>> fit_x, held_x;
  std::vector<std::array<double, 2>> fit_y, held_model, held_given;
  std::vector<bool> validation;
  double torque_ss[2] = {0, 0}, torque_rows = 0;  // the measured torque on the held-out rows
  for (const Rec& rc : recs) {
    if (rc.n() < 2) continue;
    for (size_t i = rc.split; i < rc.n(); ++i)
      for (int j = 0; j < 2; ++j) torque_ss[j] += rc.raw[j][i] * rc.raw[j][i];
    torque_rows += static_cast<double>(rc.n() - rc.split);
    const RecordResiduals res = ResidualsOf(given, model, rc, DiagnoseThreads(opt));
    const double fs = static_cast<double>(rc.n() - 1) / (rc.kin.t.back() - rc.kin.t.front());
    const size_t step = CompletenessStep(fs, rc.hz);
    if (step0 == 0) step0 = step;
    for (int j = j0; j < 2; ++j) segs[j].push_back(SegmentOf(rc, res, j, step));
    const size_t h = std::max<size_t>(1, static_cast<size_t>(std::lround(kHistoryS * fs)));
    const size_t valid_from = 2 * h + static_cast<size_t>((1 - kValidationShare) * static_cast<double>(rc.split - std::min(rc.split, 2 * h)));
    std::array<double, kInputs> x;
    for (size_t i = 2 * h; i < rc.split; i += fit_stride) {
      InputsAt(rc, res, i, h, x.data());
      fit_x.push_back(x);
      fit_y.push_back({res.model[0][i], res.model[1][i]});
      validation.push_back(i >= valid_from);
    }
    for (size_t i = std::max(rc.split, 2 * h); i < rc.n(); i += held_stride) {
      InputsAt(rc, res, i, h, x.data());
      held_x.push_back(x);
      held_model.push_back({res.model[0][i], res.model[1][i]});
      held_given.push_back({res.given[0][i], res.given[1][i]});
    }
  }
  // The material floor: the selection's (kMinTorqueShare of the measured torque's RMS).
  for (int j = j0; j < 2; ++j)
    out.completeness[j] = AssessCompleteness(segs[j], std::max<size_t>(step0, 1),
                                             kMinTorqueShare * std::sqrt(torque_ss[j] / std::max(torque_rows, 1.0)));

  const size_t nv = static_cast<size_t>(std::count(validation.begin(), validation.end(), true));
  if (held_x.empty() || nv == 0 || nv == validation.size()) return out;
  auto Matrix = [](const auto& rows) {
    Eigen::MatrixXd M(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows[0].size()));
    for (size_t i = 0; i < rows.size(); ++i)
      for (size_t c = 0; c < rows[0].size(); ++c) M(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = rows[i][c];
    return M;
  };
  const BlackBox bb = BlackBox::Fit(Matrix(fit_x), Matrix(fit_y), validation);
  const Eigen::MatrixXd pred = bb.Predict(Matrix(held_x));
  for (int j = j0; j < 2; ++j) {
    double given_sse = 0, model_sse = 0, bb_sse = 0;
    for (size_t i = 0; i < held_x.size(); ++i) {
      given_sse += held_given[i][j] * held_given[i][j];
      model_sse += held_model[i][j] * held_model[i][j];
      bb_sse += std::pow(held_model[i][j] - pred(static_cast<Eigen::Index>(i), j), 2);
    }
    JointCeiling& c = out.ceiling[j];
    c.train_rows = fit_x.size(), c.heldout_rows = held_x.size();
    if (!(given_sse > 0)) continue;
    c.done = true;
    c.given_rms = std::sqrt(given_sse / static_cast<double>(held_x.size()));
    c.named_pct = 100 * (1 - model_sse / given_sse);
    c.black_box_pct = 100 * (1 - bb_sse / given_sse);
  }
  return out;
}

std::array<JointCompleteness, 2> CompletenessOnFitRows(const LegParams& given, const LegParams& model,
                                                      const std::vector<Rec>& recs, const DiagnoseOptions& opt) {
  std::array<JointCompleteness, 2> out;
  const int j0 = given.one_joint ? 1 : 0;
  std::vector<ResidualSegment> segs[2];
  size_t step0 = 0;
  double torque_ss[2] = {0, 0}, rows = 0;
  for (const Rec& rc : recs) {
    if (rc.split < 2) continue;
    for (size_t i = 0; i < rc.split; ++i)
      for (int j = 0; j < 2; ++j) torque_ss[j] += rc.raw[j][i] * rc.raw[j][i];
    rows += static_cast<double>(rc.split);
    const RecordResiduals res = ResidualsOf(given, model, rc, DiagnoseThreads(opt));
    const double fs = static_cast<double>(rc.n() - 1) / (rc.kin.t.back() - rc.kin.t.front());
    const size_t step = CompletenessStep(fs, rc.hz);
    if (step0 == 0) step0 = step;
    for (int j = j0; j < 2; ++j) segs[j].push_back(SegmentOf(rc, res, j, step, 0, rc.split));
  }
  for (int j = j0; j < 2; ++j)
    out[j] = AssessCompleteness(segs[j], std::max<size_t>(step0, 1),
                                kMinTorqueShare * std::sqrt(torque_ss[j] / std::max(rows, 1.0)));
  return out;
}

ModelAssessment AssessModelOnRecords(const LegParams& given, const LegParams& model,
                                     const std::vector<const MeasuredData*>& records, const CutoffChoice& cutoff,
                                     const DiagnoseOptions& opt) {
  std::vector<Rec> recs(records.size());  // in place: Rec::FilterFn captures its record
  for (size_t r = 0; r < records.size(); ++r)
    PrepareRecord(given, *records[r], nullptr, cutoff, opt.holdout_fraction, DiagnoseThreads(opt), &recs[r]);
  return AssessModel(given, model, recs, opt);
}

}  // namespace torque_fit
}  // namespace exotwin
