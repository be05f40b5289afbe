#include "diagnosis/derivative_cutoff.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <memory>

#include <Eigen/Eigenvalues>

#include "formats/number_text.h"
#include "dsp/statistics.h"
#include "core/error.h"
#include "core/parallel_for.h"
#include "model/regressors.h"

namespace exotwin {
namespace {

constexpr double kCandidatesHz[] = {1.5, 2, 3, 4, 5, 7, 10, 14, 20, 30, 50};
constexpr double kTrainFraction = 0.7;
constexpr size_t kMaxRowsPerRecord = 20000;
constexpr int kCols = 6 + 2 * 3;  // lumped [J1 J2 X1 X2 Y1 Y2], per joint offset, Coulomb, viscous

// Regressor rows (hip, knee) of the generic torque model at sample i of angles q, rates qd, qdd;
// target tau_R = -tau_S.
void RegressorRows(double L1, double g, const std::vector<double>* q[2], const std::vector<double>* qd[2],
                   const std::vector<double>* qdd[2], size_t i, Eigen::Matrix<double, 2, kCols>* Y) {
  Y->setZero();
  Y->leftCols<6>() = FullRegressor(L1, g, {(*q[0])[i], (*q[1])[i]}, {(*qd[0])[i], (*qd[1])[i]},
                                   {(*qdd[0])[i], (*qdd[1])[i]});
  for (int j = 0; j < 2; ++j) {
    const double v = (*qd[j])[i];
    (*Y)(j, 6 + 3 * j) = 1.0;
    (*Y)(j, 7 + 3 * j) = v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
    (*Y)(j, 8 + 3 * j) = v;
  }
}

// What no candidate cutoff changes in a record: its sampling, the rows scored, the recorded rate
// columns, and (parallel filtering) the angles' trigonometry per sample.
struct RecordBase {
  Sampling sampling;
  std::vector<size_t> at;  // the rows: every stride-th sample, filter edges left out
  size_t split = 0;        // first held-out sample
  const std::vector<double>* recorded[2][2] = {{nullptr, nullptr}, {nullptr, nullptr}};  // qd_*, qdd_*
  std::unique_ptr<RegressorTrig[]> trig;  // per sample (not zeroed: the threads that fill it touch its pages)
};


// Torque variance per joint over all records (the score's normalization), at least 1e-12.
void TorqueVariance(const std::vector<const MeasuredData*>& records, double var[2]) {
  for (int j = 0; j < 2; ++j) {
    double s = 0, ss = 0, n = 0;
    for (const MeasuredData* d : records)
      for (double v : j == 0 ? d->tau_hip() : d->tau_knee()) s += v, ss += v * v, n += 1;
    var[j] = std::max(ss / n - (s / n) * (s / n), 1e-12);
  }
}

// A joint held still with no torque in every record (a one-joint record's embedded hip, DESIGN.md
// "One-joint devices") carries no information: its rows are left out of the fit and the score.
void AbsentJoints(const std::vector<const MeasuredData*>& records, bool absent[2]) {
  for (int j = 0; j < 2; ++j) {
    absent[j] = true;
    for (const MeasuredData* d : records) {
      const std::vector<double>& q = j == 0 ? d->q_hip() : d->q_knee();
      const std::vector<double>& tau = j == 0 ? d->tau_hip() : d->tau_knee();
      absent[j] = absent[j] && std::all_of(q.begin(), q.end(), [](double v) { return v == 0; }) &&
                  std::all_of(tau.begin(), tau.end(), [](double v) { return v == 0; });
    }
  }
}

// Every record's RecordBase; with parallel filtering its angles' trigonometry on `threads` threads.
std::vector<RecordBase> RecordBases(const std::vector<const MeasuredData*>& records, bool parallel,
                                    int threads_of_records) {
  std::vector<RecordBase> base(records.size());
  for (size_t r = 0; r < records.size(); ++r) {
    const MeasuredData& d = *records[r];
    RecordBase& B = base[r];
    const size_t n = d.size();
    B.sampling = ExamineSampling(d.t(), d.source);
    const size_t edge = std::min<size_t>(n / 20, static_cast<size_t>(0.5 / B.sampling.dt));  // filter edges
    B.split = static_cast<size_t>(kTrainFraction * static_cast<double>(n));
    const size_t stride = std::max<size_t>(1, n / kMaxRowsPerRecord);
    for (size_t i = edge; i + edge < n; i += stride) B.at.push_back(i);
    const char* names[2] = {"hip", "knee"};
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) B.recorded[j][k] = d.Column(std::string(k == 0 ? "qd_" : "qdd_") + names[j]);
    if (parallel) {
      B.trig.reset(new RegressorTrig[n]);  // here: the threads below allocate nothing
      ParallelForRanges(n, threads_of_records, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) B.trig[i] = TrigOf({d.q_hip()[i], d.q_knee()[i]});
      });
    }
  }
  return base;
}

constexpr size_t kBatch = 6;  // columns low-passed together (memory: kBatch records)

// A candidate cutoff's rows of one record: the regressor (parallel: from the angles differentiated at
// DerivativeCutoffHz(fc), each column and the torque low-passed at fc; else differentiated at fc), the
// torque it is fitted to, the raw torque the score is taken against, and whether a row is in the fit
// part.
struct Rows {
  std::vector<Eigen::Matrix<double, 2, kCols>> Y;
  std::vector<Eigen::Vector2d> u_f, u_raw;
  std::vector<bool> train;
};

// Parallel filtering's rows of record d at cutoff fc into *R_out (sized): each column of
// RegressorRows over all samples, low-passed, taken at the rows, then the torque; kBatch at a time
// through one low-pass, each batch's halves on `threads` threads (batch: the reused columns).
void FilteredRows(const MeasuredData& d, const RecordBase& B, double fc, double L1, double g, int threads,
                  const std::vector<double>* const qd[2], const std::vector<double>* const qdd[2],
                  std::vector<double> batch[kBatch], Rows* R_out) {
  Rows& R = *R_out;
  const size_t n = d.size();
  const std::vector<size_t>& at = B.at;
  const std::vector<double>* tau[2] = {&d.tau_hip(), &d.tau_knee()};
  // Each column of RegressorRows over all samples, low-passed, taken at the rows, then the
  // torque; eight at a time through one low-pass. The columns RegressorRows leaves zero stay
  // zero (the low-pass of zeros is zero).
  const TimeBaseLowPass low(B.sampling, d.t(), fc, d.source);
  enum Kind { kRegressor, kOnes, kSign, kRate, kTorque };
  struct Col {
    Kind kind;
    int j, col;  // row and column of R.Y (kOnes: both offsets; kTorque: u_f)
  };
  static constexpr Col kFiltered[] = {
      {kRegressor, 0, 0}, {kRegressor, 0, 1}, {kRegressor, 0, 2}, {kRegressor, 0, 3},
      {kRegressor, 0, 4}, {kRegressor, 0, 5}, {kRegressor, 1, 1}, {kRegressor, 1, 3},
      {kRegressor, 1, 5}, {kOnes, 0, 6},      {kSign, 0, 7},      {kSign, 1, 10},
      {kRate, 0, 8},      {kRate, 1, 11},     {kTorque, 0, 0},    {kTorque, 1, 0}};
  for (size_t c0 = 0; c0 < std::size(kFiltered); c0 += kBatch) {
    const size_t K = std::min(kBatch, std::size(kFiltered) - c0);
    for (size_t e = 0; e < K; ++e) batch[e].resize(n);  // here: the threads below allocate nothing
    // Each half of the batch on its own thread: its columns generated block by block and
    // low-passed as they come (TimeBaseLowPass::ApplyGenerated), the regressor evaluated where
    // the half holds one of its columns.
    ParallelFor(2, threads, [&](size_t half) {
      const size_t e0 = half * K / 2, e1 = (half + 1) * K / 2;
      if (e1 == e0) return;
      std::vector<double>* ptr[kBatch];
      double* reg_out[kBatch];  // the half's regressor columns and their entries of Y
      int reg_j[kBatch], reg_col[kBatch], regressors = 0;
      for (size_t e = e0; e < e1; ++e) {
        ptr[e - e0] = &batch[e];
        const Col& c = kFiltered[c0 + e];
        if (c.kind == kRegressor)
          reg_out[regressors] = batch[e].data(), reg_j[regressors] = c.j, reg_col[regressors++] = c.col;
      }
      low.ApplyGenerated(ptr, e1 - e0, [&](size_t begin, size_t end) {
        if (regressors > 0)
          for (size_t i = begin; i < end; ++i) {
            const Matrix26 Y =
                FullRegressorOfTrig(L1, g, B.trig[i], {(*qd[0])[i], (*qd[1])[i]}, {(*qdd[0])[i], (*qdd[1])[i]});
            for (int k = 0; k < regressors; ++k) reg_out[k][i] = Y(reg_j[k], reg_col[k]);
          }
        for (size_t e = e0; e < e1; ++e) {
          const Col& c = kFiltered[c0 + e];
          double* v = batch[e].data();
          switch (c.kind) {
            case kRegressor: break;
            case kOnes: std::fill(v + begin, v + end, 1.0); break;
            case kRate: std::copy(qd[c.j]->begin() + begin, qd[c.j]->begin() + end, v + begin); break;
            case kTorque: std::copy(tau[c.j]->begin() + begin, tau[c.j]->begin() + end, v + begin); break;
            case kSign:
              for (size_t i = begin; i < end; ++i) {
                const double w = (*qd[c.j])[i];
                v[i] = w > 0 ? 1.0 : (w < 0 ? -1.0 : 0.0);
              }
              break;
          }
        }
      });
      // The half's columns taken at the rows (each column its own entries of the rows).
      for (size_t e = e0; e < e1; ++e) {
        const Col& c = kFiltered[c0 + e];
        const std::vector<double>& v = batch[e];
        for (size_t a = 0; a < at.size(); ++a) {
          if (c.kind == kTorque) {
            R.u_f[a][c.j] = -v[at[a]], R.u_raw[a][c.j] = -(*tau[c.j])[at[a]];
          } else if (c.kind == kOnes) {
            R.Y[a](0, 6) = v[at[a]], R.Y[a](1, 9) = v[at[a]];
          } else {
            R.Y[a](c.j, c.col) = v[at[a]];
          }
        }
      }
    });
  }
}

// Record d's rows at candidate cutoff fc (Rows) into *R_out, their fit part's normal equations added
// to *A_io, *b_io; derived_buffer and batch: reused vectors.
void RecordRows(const MeasuredData& d, const RecordBase& B, double fc, bool parallel, double L1, double g,
                int threads_of_records, const bool absent[2], AngleRates derived_buffer[2],
                std::vector<double> batch[kBatch], Rows* R_out, Eigen::Matrix<double, kCols, kCols>* A_io,
                Eigen::Matrix<double, kCols, 1>* b_io) {
  const size_t n = d.size();
  const std::vector<size_t>& at = B.at;
  // The rates DeriveKinematics(d, cutoff) gives: a recorded column as recorded.
  const double cutoff = parallel ? DerivativeCutoffHz(fc, 1.0 / B.sampling.dt) : fc;
  AngleRates* derived = derived_buffer;
  const int threads = n < kMinSamplesToSplit ? 1 : threads_of_records;
  const std::vector<double>* q[2] = {&d.q_hip(), &d.q_knee()};
  const std::vector<double>* qd[2];
  const std::vector<double>* qdd[2];
  for (int j = 0; j < 2; ++j)  // sized here: the threads write into them, allocating nothing (a
    derived[j].qd.reserve(n), derived[j].qdd.reserve(n);  // block freed in a thread's arena stays there)
  ParallelFor(2, threads, [&](size_t j) {
    if (!B.recorded[j][0] || !B.recorded[j][1])
      DeriveAngleRatesInto(B.sampling, d.t(), *q[j], cutoff, d.source, &derived[j]);
  });
  for (int j = 0; j < 2; ++j) {
    qd[j] = B.recorded[j][0] ? B.recorded[j][0] : &derived[j].qd;
    qdd[j] = B.recorded[j][1] ? B.recorded[j][1] : &derived[j].qdd;
  }
  Rows& R = *R_out;
  Eigen::Matrix<double, kCols, kCols>& A = *A_io;
  Eigen::Matrix<double, kCols, 1>& b = *b_io;
  R.Y.assign(at.size(), Eigen::Matrix<double, 2, kCols>::Zero());
  R.u_f.resize(at.size()), R.u_raw.resize(at.size()), R.train.resize(at.size());
  const std::vector<double>* tau[2] = {&d.tau_hip(), &d.tau_knee()};
  if (!parallel) {
    for (size_t a = 0; a < at.size(); ++a) RegressorRows(L1, g, q, qd, qdd, at[a], &R.Y[a]);
    for (int j = 0; j < 2; ++j)
      for (size_t a = 0; a < at.size(); ++a) R.u_f[a][j] = -(*tau[j])[at[a]], R.u_raw[a][j] = -(*tau[j])[at[a]];
  } else {
    FilteredRows(d, B, fc, L1, g, threads, qd, qdd, batch, &R);
  }
  for (int j = 0; j < 2; ++j)
    if (absent[j])
      for (size_t a = 0; a < at.size(); ++a) R.Y[a].row(j).setZero(), R.u_f[a][j] = 0, R.u_raw[a][j] = 0;
  for (size_t a = 0; a < at.size(); ++a) {
    R.train[a] = at[a] < B.split;
    if (!R.train[a]) continue;
    A.noalias() += R.Y[a].transpose() * R.Y[a];
    b.noalias() += R.Y[a].transpose() * R.u_f[a];
  }
}

// The generic fit of a candidate cutoff from its normal equations A, b, scored on the held-out rows
// against the raw torque: its held-out RMS errors and score into *c_io, each row's score into a new
// entry of *row_scores.
void ScoreCandidate(const std::vector<Rows>& rows, const Eigen::Matrix<double, kCols, kCols>& A,
                    const Eigen::Matrix<double, kCols, 1>& b, const double var[2], CutoffChoice* c_io,
                    std::vector<std::vector<double>>* row_scores_io) {
  CutoffChoice& c = *c_io;
  std::vector<std::vector<double>>& row_scores = *row_scores_io;
  // Least squares on the column-normalized normal equations; directions the motion does not
  // excite (e.g. a joint held still) are dropped by an eigenvalue floor.
  Eigen::Matrix<double, kCols, 1> s = A.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, kCols, kCols> An = s.asDiagonal() * A * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kCols, kCols>> es(An);
  Eigen::Matrix<double, kCols, 1> inv = Eigen::Matrix<double, kCols, 1>::Zero();
  const double top = es.eigenvalues().maxCoeff();
  for (int i = 0; i < kCols; ++i)
    if (es.eigenvalues()[i] > 1e-9 * top) inv[i] = 1.0 / es.eigenvalues()[i];
  const Eigen::Matrix<double, kCols, 1> theta =
      s.asDiagonal() * (es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose()) *
      s.asDiagonal() * b;
  double sse[2] = {0, 0}, cnt = 0;
  std::vector<double>& scores = row_scores.emplace_back();
  for (const Rows& R : rows)
    for (size_t a = 0; a < R.Y.size(); ++a) {
      if (R.train[a]) continue;
      const Eigen::Vector2d e = R.u_raw[a] - R.Y[a] * theta;
      sse[0] += e[0] * e[0], sse[1] += e[1] * e[1], cnt += 1;
      scores.push_back(e[0] * e[0] / var[0] + e[1] * e[1] / var[1]);
    }
  cnt = std::max(cnt, 1.0);
  for (int j = 0; j < 2; ++j) c.heldout_rmse[j].push_back(std::sqrt(sse[j] / cnt));
  c.score.push_back(sse[0] / cnt / var[0] + sse[1] / cnt / var[1]);  // = mean of scores
}

// The choice among the scored candidates (c_io's score, heldout_rmse): c->score_se, c->hz, c->why.
void PickCutoff(bool parallel, const std::vector<std::vector<double>>& row_scores, CutoffChoice* c_io) {
  CutoffChoice& c = *c_io;
  const size_t at_best = static_cast<size_t>(std::min_element(c.score.begin(), c.score.end()) - c.score.begin());
  // Each candidate against the best on the same held-out rows: the mean of the paired differences
  // and its standard error (the rows' spread and autocorrelation length), so that what both fits
  // miss alike cancels.
  c.score_se.assign(c.score.size(), 0.0);
  size_t pick = at_best;
  for (size_t i = 0; i < c.score.size(); ++i) {
    std::vector<double> diff(row_scores[i].size());
    for (size_t a = 0; a < diff.size(); ++a) diff[a] = row_scores[i][a] - row_scores[at_best][a];
    const double n = static_cast<double>(diff.size()), mean = c.score[i] - c.score[at_best];
    double ss = 0;
    for (double x : diff) ss += (x - mean) * (x - mean);
    const double tau = AutocorrelationLength(diff.data(), diff.size());
    c.score_se[i] = n > 1 ? std::sqrt(ss / (n - 1) * tau / n) : 0.0;
    if (i < pick && mean <= c.score_se[i]) pick = i;
  }
  c.hz = c.candidates_hz[pick];
  c.why = "lowest cutoff within one standard error (paired, on the same rows) of the least held-out error of a "
          "generic rigid two-link + friction + offset fit" + std::string(parallel ? " filtered alike" : "") +
          " (last 30 % of each record, against the raw torque): " + NumberText(c.hz) + " Hz (held-out rmse hip " + NumberText(c.heldout_rmse[0][pick]) + ", knee " +
          NumberText(c.heldout_rmse[1][pick]) + " N m; best " + NumberText(c.candidates_hz[at_best]) + " Hz, 20 Hz " +
          [&] {
            for (size_t i = 0; i < c.candidates_hz.size(); ++i)
              if (c.candidates_hz[i] == 20.0)
                return NumberText(c.heldout_rmse[0][i]) + " / " + NumberText(c.heldout_rmse[1][i]) + " N m";
            return std::string("not a candidate");
          }() + ")";
}

}  // namespace

double DerivativeCutoffHz(double fc, double fs) { return std::min(kDerivativeCutoffFactor * fc, 0.4 * fs); }

double ParseCutoffOption(const std::string& value, const std::string& what) {
  if (value == "auto") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (end == value.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0))
    throw InputError(what + ": '" + value + "', expected a cutoff in Hz (> 0) or 'auto'");
  return v;
}

double ResolveCutoffOption(const std::string& value, const std::string& what,
                           const std::vector<const MeasuredData*>& records, double L1, double g,
                           std::string* why) {
  const double hz = ParseCutoffOption(value, what);
  if (hz > 0) {
    if (why) *why = "given (" + what + " " + NumberText(hz) + ")";
    return hz;
  }
  const CutoffChoice c = ChooseCutoff(records, L1, g, CutoffUse::kDerivatives);
  if (why) *why = c.why;
  return c.from_columns ? 20.0 : c.hz;
}

CutoffChoice ChooseCutoff(const std::vector<const MeasuredData*>& records, double L1, double g,
                          CutoffUse use, int threads_asked) {
  const bool parallel = use == CutoffUse::kParallel;
  CutoffChoice c;
  if (records.empty()) throw InputError("cutoff choice: no record");
  double fs_min = 1e300;
  bool all_columns = true;
  for (const MeasuredData* d : records) {
    if (d->size() < 200)
      throw InputError(d->source + ": " + std::to_string(d->size()) +
                       " samples, expected at least 200 to choose the derivative cutoff");
    fs_min = std::min(fs_min, 1.0 / MedianStep(d->t()));
    for (const char* n : {"qd_hip", "qdd_hip", "qd_knee", "qdd_knee"}) all_columns &= d->Column(n) != nullptr;
  }
  if (all_columns) {
    c.from_columns = true;
    c.hz = 0;
    c.why = "every record has qd_* and qdd_* columns: they are used as measured, no filter";
    return c;
  }
  for (double f : kCandidatesHz)
    if (f < 0.25 * fs_min) c.candidates_hz.push_back(f);
  if (c.candidates_hz.empty())
    throw InputError(records[0]->source + ": sample rate " + NumberText(fs_min) +
                     " Hz is too low to differentiate the angles, expected above 6 Hz");
  double var[2] = {0, 0};
  TorqueVariance(records, var);
  bool absent[2];
  AbsentJoints(records, absent);
  // Threads of the per-sample loops and the candidates' work below (at most 2).
  const int threads_of_records =
      std::min(2, threads_asked > 0 ? threads_asked : MachineCores());
  const std::vector<RecordBase> base = RecordBases(records, parallel, threads_of_records);
  std::vector<std::vector<double>> row_scores;  // per candidate: each held-out row's score
  std::vector<double> batch[kBatch];
  // The work of a candidate on two threads where it splits without more memory: the two angles'
  // rates (each into its own reused vectors), a batch's columns by halves, each half generated block by
  // block and low-passed as it comes (each signal filtered as alone). The same bits on any thread count.
  AngleRates derived_buffer[2];  // the rates of the record at hand, its vectors reused
  for (double fc : c.candidates_hz) {
    std::vector<Rows> rows(records.size());
    Eigen::Matrix<double, kCols, kCols> A = Eigen::Matrix<double, kCols, kCols>::Zero();
    Eigen::Matrix<double, kCols, 1> b = Eigen::Matrix<double, kCols, 1>::Zero();
    for (size_t r = 0; r < records.size(); ++r)
      RecordRows(*records[r], base[r], fc, parallel, L1, g, threads_of_records, absent, derived_buffer, batch, &rows[r],
                 &A, &b);
    ScoreCandidate(rows, A, b, var, &c, &row_scores);
  }
  PickCutoff(parallel, row_scores, &c);
  return c;
}

}  // namespace exotwin
