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

ModelAssessment TestModel(const LegParams& given, const LegParams& model, const std::vector<Rec>& recs,
                          const DiagnoseOptions& opt, CeilingRows* rows,
                          std::array<JointCompleteness, 2>* on_fit_rows) {
  ModelAssessment out;
  const int j0 = given.one_joint ? 1 : 0;  // a one-joint device: the held hip is no data
  std::vector<ResidualSegment> segs[2], fit_segs[2];
  size_t step0 = 0;
  // The black box's rows: the strides that keep them within the limits.
  size_t fit_total = 0, held_total = 0;
  for (const Rec& rc : recs) fit_total += rc.split, held_total += rc.n() - rc.split;
  const size_t fit_stride = std::max<size_t>(1, (fit_total + kBlackBoxFitRows - 1) / kBlackBoxFitRows);
  const size_t held_stride = std::max<size_t>(1, (held_total + kBlackBoxHeldOutRows - 1) / kBlackBoxHeldOutRows);
  const bool first = rows->models == 0;  // the inputs and the model given's residual: once
  std::vector<std::array<double, kInputs>> fit_x, held_x;
  std::vector<std::array<double, 2>> fit_y, held_model, held_given;
  std::vector<bool> validation;
  // The measured torque's sum of squares on the held-out rows and on the fit rows.
  double torque_ss[2] = {0, 0}, torque_rows = 0, fit_ss[2] = {0, 0}, fit_rows = 0;
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
    if (on_fit_rows && rc.split >= 2) {
      for (size_t i = 0; i < rc.split; ++i)
        for (int j = 0; j < 2; ++j) fit_ss[j] += rc.raw[j][i] * rc.raw[j][i];
      fit_rows += static_cast<double>(rc.split);
      for (int j = j0; j < 2; ++j) fit_segs[j].push_back(SegmentOf(rc, res, j, step, 0, rc.split));
    }
    const size_t h = std::max<size_t>(1, static_cast<size_t>(std::lround(kHistoryS * fs)));
    const size_t valid_from = 2 * h + static_cast<size_t>((1 - kValidationShare) * static_cast<double>(rc.split - std::min(rc.split, 2 * h)));
    std::array<double, kInputs> x;
    for (size_t i = 2 * h; i < rc.split; i += fit_stride) {
      if (first) {
        InputsAt(rc, res, i, h, x.data());
        fit_x.push_back(x);
        validation.push_back(i >= valid_from);
      }
      fit_y.push_back({res.model[0][i], res.model[1][i]});
    }
    for (size_t i = std::max(rc.split, 2 * h); i < rc.n(); i += held_stride) {
      if (first) {
        InputsAt(rc, res, i, h, x.data());
        held_x.push_back(x);
        held_given.push_back({res.given[0][i], res.given[1][i]});
      }
      held_model.push_back({res.model[0][i], res.model[1][i]});
    }
  }
  // The material floor: the selection's (kMinTorqueShare of the measured torque's RMS).
  for (int j = j0; j < 2; ++j)
    out.completeness[j] = AssessCompleteness(segs[j], std::max<size_t>(step0, 1),
                                             kMinTorqueShare * std::sqrt(torque_ss[j] / std::max(torque_rows, 1.0)));
  if (on_fit_rows)
    for (int j = j0; j < 2; ++j)
      (*on_fit_rows)[j] = AssessCompleteness(fit_segs[j], std::max<size_t>(step0, 1),
                                             kMinTorqueShare * std::sqrt(fit_ss[j] / std::max(fit_rows, 1.0)));
  auto Matrix = [](const auto& v) {
    Eigen::MatrixXd M(static_cast<Eigen::Index>(v.size()), static_cast<Eigen::Index>(v.empty() ? 0 : v[0].size()));
    for (size_t i = 0; i < v.size(); ++i)
      for (size_t c = 0; c < v[0].size(); ++c) M(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = v[i][c];
    return M;
  };
  if (first) {
    rows->fit_x = Matrix(fit_x), rows->held_x = Matrix(held_x), rows->held_given = Matrix(held_given);
    rows->validation = std::move(validation);
    rows->one_joint = given.one_joint.has_value();
  }
  auto Append = [&](Eigen::MatrixXd* to, const Eigen::MatrixXd& cols) {
    Eigen::MatrixXd grown(cols.rows(), to->cols() + cols.cols());
    grown << *to, cols;
    *to = std::move(grown);
  };
  if (first) rows->fit_y = Eigen::MatrixXd(fit_y.size(), 0), rows->held_y = Eigen::MatrixXd(held_model.size(), 0);
  Append(&rows->fit_y, Matrix(fit_y));
  Append(&rows->held_y, Matrix(held_model));
  ++rows->models;
  return out;
}

double BlackBoxShareOfResidual(const JointCeiling& c) {
  const double left = 1 - c.named_pct / 100;  // what the named model leaves of the model given's SSE
  return c.done && left > 0 ? (c.black_box_pct - c.named_pct) / 100 / left : 0.0;
}

bool CeilingLeavesStructure(const JointCeiling& c, double floor) {
  if (!c.done) return false;
  const double removed = (c.black_box_pct - c.named_pct) / 100;  // of the model given's held-out SSE
  return BlackBoxShareOfResidual(c) >= kMinHeldoutGain && c.given_rms * std::sqrt(std::max(0.0, removed)) >= floor;
}

void FitCeilings(const CeilingRows& rows, const std::vector<ModelAssessment*>& out, const DiagnoseOptions& opt) {
  const std::vector<bool>& validation = rows.validation;
  const size_t nv = static_cast<size_t>(std::count(validation.begin(), validation.end(), true));
  if (rows.held_x.rows() == 0 || nv == 0 || nv == validation.size()) return;
  BlackBoxOptions bo;
  bo.threads = DiagnoseThreads(opt);
  const BlackBox bb = BlackBox::Fit(rows.fit_x, rows.fit_y, validation, bo);
  const Eigen::MatrixXd pred = bb.Predict(rows.held_x);
  const Eigen::Index m = rows.held_x.rows();
  for (size_t k = 0; k < out.size() && static_cast<int>(k) < rows.models; ++k)
    for (int j = rows.one_joint ? 1 : 0; j < 2; ++j) {
      const Eigen::Index col = 2 * static_cast<Eigen::Index>(k) + j;
      double given_sse = 0, model_sse = 0, bb_sse = 0;
      for (Eigen::Index i = 0; i < m; ++i) {
        given_sse += rows.held_given(i, j) * rows.held_given(i, j);
        model_sse += rows.held_y(i, col) * rows.held_y(i, col);
        bb_sse += std::pow(rows.held_y(i, col) - pred(i, col), 2);
      }
      JointCeiling& c = out[k]->ceiling[j];
      c.train_rows = static_cast<size_t>(rows.fit_x.rows()), c.heldout_rows = static_cast<size_t>(m);
      if (!(given_sse > 0)) continue;
      c.done = true;
      c.given_rms = std::sqrt(given_sse / static_cast<double>(m));
      c.named_pct = 100 * (1 - model_sse / given_sse);
      c.black_box_pct = 100 * (1 - bb_sse / given_sse);
    }
}

ModelAssessment AssessModel(const LegParams& given, const LegParams& model, const std::vector<Rec>& recs,
                            const DiagnoseOptions& opt) {
  CeilingRows rows;
  ModelAssessment out = TestModel(given, model, recs, opt, &rows, nullptr);
  FitCeilings(rows, {&out}, opt);
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
