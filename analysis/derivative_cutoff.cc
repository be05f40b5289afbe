#include "analysis/derivative_cutoff.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include "model/input_error.h"
#include "model/regressors.h"

namespace exotwin {
namespace {

constexpr double kCandidatesHz[] = {1.5, 2, 3, 4, 5, 7, 10, 14, 20, 30, 50};
constexpr double kTrainFraction = 0.7;
constexpr double kWithinBest = 0.02;  // the highest cutoff within 2 % of the best score wins
constexpr size_t kMaxRowsPerRecord = 20000;
constexpr int kCols = 6 + 2 * 3;  // lumped [J1 J2 X1 X2 Y1 Y2], per joint offset, Coulomb, viscous

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%g", v);
  return b;
}

// Regressor rows (hip, knee) of the generic torque model at one sample; target tau_R = -tau_S.
void Rows(double L1, double g, const Kinematics& k, size_t i, Eigen::Matrix<double, 2, kCols>* Y) {
  Y->setZero();
  Y->leftCols<6>() = FullRegressor(L1, g, {k.q[0][i], k.q[1][i]}, {k.qd[0][i], k.qd[1][i]},
                                   {k.qdd[0][i], k.qdd[1][i]});
  for (int j = 0; j < 2; ++j) {
    const double v = k.qd[j][i];
    (*Y)(j, 6 + 3 * j) = 1.0;
    (*Y)(j, 7 + 3 * j) = v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
    (*Y)(j, 8 + 3 * j) = v;
  }
}

}  // namespace

double ParseCutoffOption(const std::string& value, const std::string& what) {
  if (value == "auto") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (end == value.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0))
    throw InputError(what + ": '" + value + "', expected a cutoff in Hz (> 0) or 'auto'");
  return v;
}

CutoffChoice ChooseCutoff(const std::vector<const MeasuredData*>& records, double L1, double g) {
  CutoffChoice c;
  if (records.empty()) throw InputError("cutoff choice: no record");
  double fs_min = 1e300;
  bool all_columns = true;
  for (const MeasuredData* d : records) {
    if (d->size() < 200)
      throw InputError(d->source + ": " + std::to_string(d->size()) +
                       " samples, expected at least 200 to choose the derivative cutoff");
    fs_min = std::min(fs_min, 1.0 / MedianStep(d->t));
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
    throw InputError(records[0]->source + ": sample rate " + Num(fs_min) +
                     " Hz is too low to differentiate the angles, expected above 6 Hz");
  // Torque variance per joint over all records (the score's normalization).
  double var[2] = {0, 0};
  for (int j = 0; j < 2; ++j) {
    double s = 0, ss = 0, n = 0;
    for (const MeasuredData* d : records)
      for (double v : j == 0 ? d->tau_hip : d->tau_knee) s += v, ss += v * v, n += 1;
    var[j] = std::max(ss / n - (s / n) * (s / n), 1e-12);
  }
  for (double fc : c.candidates_hz) {
    Eigen::Matrix<double, kCols, kCols> A = Eigen::Matrix<double, kCols, kCols>::Zero();
    Eigen::Matrix<double, kCols, 1> b = Eigen::Matrix<double, kCols, 1>::Zero();
    struct Held {
      Kinematics kin;
      const MeasuredData* d;
      size_t from, stride;
    };
    std::vector<Held> held;
    Eigen::Matrix<double, 2, kCols> Y;
    for (const MeasuredData* d : records) {
      Kinematics k = DeriveKinematics(*d, fc);
      const size_t n = d->size();
      const size_t edge = std::min<size_t>(n / 20, static_cast<size_t>(0.5 * fs_min));  // filter edges
      const size_t split = static_cast<size_t>(kTrainFraction * static_cast<double>(n));
      const size_t stride = std::max<size_t>(1, n / kMaxRowsPerRecord);
      for (size_t i = edge; i < split; i += stride) {
        Rows(L1, g, k, i, &Y);
        const Eigen::Vector2d u(-d->tau_hip[i], -d->tau_knee[i]);
        A.noalias() += Y.transpose() * Y;
        b.noalias() += Y.transpose() * u;
      }
      held.push_back({std::move(k), d, split, stride});
    }
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
    for (const Held& h : held) {
      const size_t n = h.d->size();
      const size_t edge = std::min<size_t>(n / 20, static_cast<size_t>(0.5 * fs_min));
      for (size_t i = h.from; i + edge < n; i += h.stride) {
        Rows(L1, g, h.kin, i, &Y);
        const Eigen::Vector2d e = Eigen::Vector2d(-h.d->tau_hip[i], -h.d->tau_knee[i]) - Y * theta;
        sse[0] += e[0] * e[0], sse[1] += e[1] * e[1], cnt += 1;
      }
    }
    cnt = std::max(cnt, 1.0);
    for (int j = 0; j < 2; ++j) c.heldout_rmse[j].push_back(std::sqrt(sse[j] / cnt));
    c.score.push_back(sse[0] / cnt / var[0] + sse[1] / cnt / var[1]);
  }
  const double best = *std::min_element(c.score.begin(), c.score.end());
  size_t pick = 0;
  for (size_t i = 0; i < c.score.size(); ++i)
    if (c.score[i] <= best * (1 + kWithinBest)) pick = i;
  c.hz = c.candidates_hz[pick];
  const size_t at_best = static_cast<size_t>(std::min_element(c.score.begin(), c.score.end()) - c.score.begin());
  c.why = "highest cutoff within " + Num(100 * kWithinBest) + " % of the least held-out error of a "
          "generic rigid two-link + friction + offset fit (last 30 % of each record, against the raw "
          "torque): " + Num(c.hz) + " Hz (held-out rmse hip " + Num(c.heldout_rmse[0][pick]) + ", knee " +
          Num(c.heldout_rmse[1][pick]) + " N m; best " + Num(c.candidates_hz[at_best]) + " Hz, 20 Hz " +
          [&] {
            for (size_t i = 0; i < c.candidates_hz.size(); ++i)
              if (c.candidates_hz[i] == 20.0)
                return Num(c.heldout_rmse[0][i]) + " / " + Num(c.heldout_rmse[1][i]) + " N m";
            return std::string("not a candidate");
          }() + ")";
  return c;
}

}  // namespace exotwin
