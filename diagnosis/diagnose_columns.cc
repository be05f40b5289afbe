#include "diagnosis/diagnose_columns.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "core/parallel_for.h"
#include "dsp/grid_phasors.h"
#include "diagnosis/effects.h"
#include "diagnosis/fit_families.h"
#include "dsp/butterworth.h"
#include "model/leg_dynamics.h"
#include "model/passive_torque.h"
#include "model/regressors.h"

namespace exotwin {

std::string Candidate::Label() const {
  return name + (axis.empty() ? "" : "." + axis) + (joint == 0 ? "(hip)" : "(knee)");
}

namespace {

constexpr size_t kPendingColumns = 4;  // PendingColumns::kPending, and SetColumn's two

// f(i) for i = 0 .. n - 1 on the machine's cores, each thread a contiguous range: for the loops that
// evaluate a column on every sample of a record (f writes only sample i's values, into vectors sized
// beforehand: a worker allocates nothing record-long). The same bits on any thread count.
template <class F>
void ForEachSample(const ColumnBank& b, size_t n, F f) {
  ParallelForRanges(n, b.threads, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) f(i);
  });
}

// The index of a new column of the bank (X grown when full).
int NewColumn(ColumnBank& b) {
  const int c = b.used++;
  if (c >= b.X.cols()) b.X.conservativeResize(Eigen::NoChange, 2 * c + 8);
  return c;
}

// The bank's low-pass of *xs[0 .. count) in place, then place(k) for each: the signals cut into
// contiguous groups of at least two, one group per thread, each group's non-zero signals interleaved
// (dsp::FiltFiltInPlace of several: each signal the same bits as filtered alone; the low-pass of zeros
// is zero) and placed on the group's thread. place(k) must write only what signal k owns.
template <class Place>
void FilterAndPlace(const ColumnBank& b, std::vector<double>* const* xs, size_t count, Place place) {
  const size_t T = std::clamp<size_t>(count / 2, 1, static_cast<size_t>(std::max(1, b.threads)));
  ParallelFor(T, static_cast<int>(T), [&](size_t h) {
    const size_t e0 = h * count / T, e1 = (h + 1) * count / T;
    if (b.filter) {
      std::vector<double>* nonzero[kPendingColumns];
      size_t K = 0;
      for (size_t k = e0; k < e1; ++k)
        if (std::any_of(xs[k]->begin(), xs[k]->end(), [](double v) { return v != 0.0; })) nonzero[K++] = xs[k];
      if (K > 0) b.filter(nonzero, K);
    }
    for (size_t k = e0; k < e1; ++k) place(k);
  });
}

// Columns evaluated on every sample of a record, waiting for the bank's low-pass: filtered kPending at
// a time and each placed in the bank by its callback (FilterAndPlace: on the thread that filtered it;
// each callback writes only its own column's rows). The record-long temporaries are at most kPending.
// Without a filter a column is placed at once.
class PendingColumns {
 public:
  static constexpr size_t kPending = kPendingColumns;
  explicit PendingColumns(ColumnBank& b) : b_(b) { xs_.reserve(kPending), place_.reserve(kPending); }
  ColumnBank& bank() { return b_; }
  size_t size() const { return xs_.size(); }
  void Add(std::vector<double> x, std::function<void(const std::vector<double>&)> place) {
    if (!b_.filter) return place(x);
    xs_.push_back(std::move(x));
    place_.push_back(std::move(place));
    if (xs_.size() >= kPending) Flush();
  }
  void Flush() {
    std::vector<std::vector<double>*> p;
    for (std::vector<double>& x : xs_) p.push_back(&x);
    FilterAndPlace(b_, p.data(), p.size(), [&](size_t k) { place_[k](xs_[k]); });
    xs_.clear();
    place_.clear();
  }

 private:
  ColumnBank& b_;
  std::vector<std::vector<double>> xs_;
  std::vector<std::function<void(const std::vector<double>&)>> place_;
};

// Joint j's rows of column c from per-sample values x (filtered), weighted by w[j].
void PlaceJointRows(ColumnBank& b, int c, const double w[2], int j, const std::vector<double>& x) {
  const size_t m = b.sample.size();
  for (size_t k = 0; k < m; ++k) b.X(j * m + k, c) = w[j] * x[b.sample[k]];
}

// Fills the bank's columns c1 and c2 from f(i, &v1, &v2), two (hip row value, knee row value) of one
// sample, as SetColumn stores per-sample values.
template <class F>
void AddColumnPair(PendingColumns& p, const double w[2], int c1, int c2, F f) {
  ColumnBank& b = p.bank();
  const size_t m = b.sample.size();
  Eigen::Vector2d x1, x2;
  if (b.filter) {
    p.Flush();  // the pending columns' temporaries gone before these four
    std::vector<double> v1[2] = {std::vector<double>(b.n), std::vector<double>(b.n)};
    std::vector<double> v2[2] = {std::vector<double>(b.n), std::vector<double>(b.n)};
    ForEachSample(b, b.n, [&](size_t i) {
      Eigen::Vector2d y1, y2;
      f(i, &y1, &y2);
      v1[0][i] = y1[0], v1[1][i] = y1[1], v2[0][i] = y2[0], v2[1][i] = y2[1];
    });
    for (int j = 0; j < 2; ++j)
      p.Add(std::move(v1[j]), [&b, w, c1, j](const std::vector<double>& x) { PlaceJointRows(b, c1, w, j, x); });
    for (int j = 0; j < 2; ++j)
      p.Add(std::move(v2[j]), [&b, w, c2, j](const std::vector<double>& x) { PlaceJointRows(b, c2, w, j, x); });
    return;
  }
  for (size_t k = 0; k < m; ++k) {
    f(b.sample[k], &x1, &x2);
    b.X(k, c1) = w[0] * x1[0], b.X(m + k, c1) = w[1] * x1[1];
    b.X(k, c2) = w[0] * x2[0], b.X(m + k, c2) = w[1] * x2[1];
  }
}

// The actuator torque R[k] = ActuatorTorque(rigid, x_k, qd, qdd) and the compliant part's torque
// C[k] = CompliantPartTorque(rigid, x_k, qd, qdd) at x_0 = q, x_1 = q + h e_j, x_2 = q - h e_j (h = kNearStep),
// equal to them up to rounding: each point's rigid torque in the regressor form Y(x_k, qd, qdd) theta
// (HJ15 eq. 18-21, model/regressors.h), one Y for both parameter sets, the sines and cosines of the
// shifted angles from those of q by the angle-addition formulas (3 sincos per sample instead of 24),
// and each point's passive moment computed once (in both), the three from one set of exponentials
// (model/passive_torque.h PassiveNearPoints, made for j and kNearStep). `total`: rigid.Total().
struct NearTorques {
  Eigen::Vector2d R[3], C[3];
};
constexpr double kNearStep = 1e-5;  // rad
NearTorques TorquesNear(const LegParams& rigid, const LumpedParams& total, const PassiveNearPoints& near_passive, int j,
                        const Eigen::Vector2d& q, const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd) {
  constexpr double kH = kNearStep;
  static const double ch = std::cos(kH), sh = std::sin(kH);
  RegressorTrig trig[3];
  trig[0] = TrigOf(q);
  trig[1] = trig[2] = trig[0];
  // sin(a +- h) = s ch +- c sh, cos(a +- h) = c ch -+ s sh, for the angles that move with q_j: th1 and
  // th1 + th2 (j = 0) or th2 and th1 + th2 (j = 1).
  auto shift = [](double* s_out, double* c_out, double s, double c, double sign) {
    *s_out = s * ch + sign * c * sh;
    *c_out = c * ch - sign * s * sh;
  };
  for (int k = 1; k < 3; ++k) {
    const double sign = k == 1 ? 1.0 : -1.0;
    RegressorTrig& t = trig[k];
    if (j == 0) shift(&t.s1, &t.c1, trig[0].s1, trig[0].c1, sign);
    else shift(&t.s2, &t.c2, trig[0].s2, trig[0].c2, sign);
    shift(&t.s12, &t.c12, trig[0].s12, trig[0].c12, sign);
  }
  const Vector6 theta_R = ToVector(total);
  NearTorques t;
  Eigen::Vector2d passive[3];
  if (rigid.human) near_passive.At(q, passive);
  for (int k = 0; k < 3; ++k) {
    const Matrix26 Y = FullRegressorOfTrig(rigid.L1, rigid.g, trig[k], qd, qdd);
    t.R[k] = Y * theta_R;
    if (!rigid.human) {  // no human: the compliant part is the whole chain
      t.C[k] = t.R[k];
      continue;
    }
    t.C[k] = Y * ToVector(*rigid.human) + passive[k];
    t.R[k] += passive[k];
  }
  return t;
}

// Column c from the values x_j(k) of its joint-j rows on the fit rows k (the other joint's rows
// zero), weighted by w as SetColumn stores them.
template <class X>
void SetJointRows(ColumnBank& b, int c, const double w[2], int j, X x_j) {
  const size_t m = b.sample.size();
  for (size_t k = 0; k < m; ++k) {
    b.X(j * m + k, c) = w[j] * x_j(k);
    b.X((1 - j) * m + k, c) = w[1 - j] * 0.0;
  }
}

// Column c as SetColumn stores per-sample values x[i] on joint j's rows (0 on the other's), once
// filtered; rows_out (optional): x filtered, on the fit rows (before the weight).
void SetJointColumn(PendingColumns& p, int c, const double w[2], int j, std::vector<double> x,
                    std::vector<double>* rows_out = nullptr) {
  ColumnBank& b = p.bank();
  p.Add(std::move(x), [&b, w, c, j, rows_out](const std::vector<double>& filtered) {
    const size_t m = b.sample.size();
    SetJointRows(b, c, w, j, [&](size_t k) { return filtered[b.sample[k]]; });
    if (rows_out) {
      rows_out->resize(m);
      for (size_t k = 0; k < m; ++k) (*rows_out)[k] = filtered[b.sample[k]];
    }
  });
}

// Appends a column of joint j alone: g(i) on its joint-j rows, zero on the other joint's (the column
// SetColumn gives for (g(i), 0) or (0, g(i)), with one record-long temporary instead of two).
template <class G>
int AddJointColumn(PendingColumns& p, const double w[2], int j, G g) {
  ColumnBank& b = p.bank();
  const int c = NewColumn(b);
  if (b.filter) {
    std::vector<double> x(b.n);
    ForEachSample(b, b.n, [&](size_t i) { x[i] = g(i); });
    SetJointColumn(p, c, w, j, std::move(x));
    return c;
  }
  const size_t m = b.sample.size();
  for (size_t k = 0; k < m; ++k) {
    b.X(j * m + k, c) = w[j] * g(b.sample[k]);
    b.X((1 - j) * m + k, c) = w[1 - j] * 0.0;
  }
  return c;
}

// Appends the column -f.link_torque(unit, state_i) (both joints' rows; `unit` at joint j with value
// 1): the first-order column of a family linear in its value. With the bank's filter, a row series
// that is zero throughout (the other joint of a one-joint form) is not filtered (SetJointColumn).
int AddLinearColumn(PendingColumns& p, const double w[2], int j, const Effect& unit, const EffectFamily& f,
                    const Kinematics& kin, double g) {
  ColumnBank& b = p.bank();
  const int c = NewColumn(b);
  const size_t n = b.filter ? b.n : b.sample.size();  // every sample for the filter, else the fit rows
  std::vector<double> x[2] = {std::vector<double>(n), std::vector<double>(n)};
  ForEachSample(b, n, [&](size_t k) {
    const size_t i = b.filter ? k : b.sample[k];
    EffectState s;
    s.q = {kin.q[0][i], kin.q[1][i]}, s.qd = {kin.qd[0][i], kin.qd[1][i]}, s.qdd = {kin.qdd[0][i], kin.qdd[1][i]};
    s.g = g;
    const Eigen::Vector2d v = f.link_torque(unit, s);
    x[0][k] = -v[0], x[1][k] = -v[1];
  });
  if (!b.filter) {
    for (size_t k = 0; k < n; ++k) b.X(k, c) = w[0] * x[0][k], b.X(n + k, c) = w[1] * x[1][k];
    return c;
  }
  if (std::all_of(x[1 - j].begin(), x[1 - j].end(), [](double v) { return v == 0.0; })) {
    std::vector<double>().swap(x[1 - j]);
    SetJointColumn(p, c, w, j, std::move(x[j]));
    return c;
  }
  for (int k = 0; k < 2; ++k)
    p.Add(std::move(x[k]), [&b, w, c, k](const std::vector<double>& v) { PlaceJointRows(b, c, w, k, v); });
  return c;
}

}  // namespace

void SetColumn(ColumnBank& b, int c, const double w[2], std::vector<double> v[2]) {
  std::vector<double>* xs[2] = {&v[0], &v[1]};
  FilterAndPlace(b, xs, 2, [&](size_t j) { PlaceJointRows(b, c, w, static_cast<int>(j), v[j]); });
}

ColumnBank BuildColumns(const LegParams& params, const Kinematics& kin,
                        const std::vector<double> tau_S[2],
                        std::vector<double> resid[2], const double w[2], size_t split,
                        size_t max_rows, ColumnFilter filter, int threads) {
  ColumnBank b;
  b.threads = threads > 0 ? threads : MachineCores();
  const size_t n = kin.t.size();
  b.filter = std::move(filter);
  b.n = n;
  const size_t stride = std::max<size_t>(1, (n + max_rows - 1) / max_rows);
  for (size_t i = 0; i < n; i += stride) {
    b.sample.push_back(i);
    b.train.push_back(i < split);
  }
  const size_t m = b.sample.size();
  b.X.resize(2 * m, 0);
  b.r.resize(2 * m);
  for (size_t k = 0; k < m; ++k) {
    b.r[k] = w[0] * resid[0][b.sample[k]];
    b.r[m + k] = w[1] * resid[1][b.sample[k]];
  }
  for (int j = 0; j < 2; ++j) std::vector<double>().swap(resid[j]);
  LegParams rigid = params;
  rigid.effects.clear();
  const LumpedParams total = rigid.Total();
  auto Q = [&](size_t i) { return Eigen::Vector2d(kin.q[0][i], kin.q[1][i]); };
  auto QD = [&](size_t i) { return Eigen::Vector2d(kin.qd[0][i], kin.qd[1][i]); };
  auto QDD = [&](size_t i) { return Eigen::Vector2d(kin.qdd[0][i], kin.qdd[1][i]); };
  const double g = params.g;
  // The envelope columns are the same at both joints but for the rows they fill: the hip's are kept
  // on the fit rows (filtered, unweighted) for the knee's.
  std::vector<std::vector<double>> envelope_rows(kin.emg.size());
  PendingColumns pc(b);
  // Its columns per joint: offset, Coulomb, viscous, inertia, gravity X and Y, stiffness, backlash,
  // strap, gain, delay, [passive moment], one per EMG channel (NewColumn grows X if more).
  b.X.resize(2 * m, 2 * (11 + (params.human && !params.one_joint ? 1 : 0) + static_cast<long>(kin.emg.size())));
  for (int j = 0; j < 2; ++j) {
    auto add = [&](const std::string& name, std::vector<int> cols, const std::string& axis = "") {
      Candidate c;
      c.name = name, c.joint = j, c.cols = std::move(cols), c.axis = axis;
      b.candidates.push_back(c);
      return &b.candidates.back();
    };
    const int off = AddJointColumn(pc, w, j, [&](size_t) { return 1.0; });
    // The families linear in their value (FitFamily::linear_column): -link_torque at value 1.
    for (const FitFamily& ff : FitFamilies()) {
      if (!ff.linear_column || (ff.candidate_for && !ff.candidate_for(params))) continue;
      for (const std::string& axis : ff.axes.empty() ? std::vector<std::string>{""} : ff.axes) {
        Effect unit;
        unit.name = ff.family->name, unit.joint = j == 0 ? "hip" : "knee", unit.value = 1.0, unit.axis = axis;
        add(ff.family->name, {AddLinearColumn(pc, w, j, unit, *ff.family, kin, g)}, axis);
      }
    }
    add("joint_stiffness", {AddJointColumn(pc, w, j, [&](size_t i) { return -kin.q[j][i]; }), off});
    // Backlash: Delta tau_S = (b/2) s(tau_R,j) dtau/dq_j (first order in b). Straps: Delta tau_S =
    // (1/k) dtau_C/dq_j tau_C,j (first order in 1/k). Both columns in one pass over the samples.
    {
      const int cb = NewColumn(b), cs = NewColumn(b);
      const PassiveNearPoints near_passive(rigid.passive, j, kNearStep);
      AddColumnPair(pc, w, cb, cs, [&](size_t i, Eigen::Vector2d* backlash, Eigen::Vector2d* strap) {
        const NearTorques t = TorquesNear(rigid, total, near_passive, j, Q(i), QD(i), QDD(i));
        const Eigen::Vector2d d = (t.R[1] - t.R[2]) / 2e-5;
        *backlash = Eigen::Vector2d(0.5 * std::tanh(t.R[0][j] / kBacklashTorqueWidth) * d);
        const Eigen::Vector2d dc = (t.C[1] - t.C[2]) / 2e-5;
        *strap = Eigen::Vector2d(dc * t.C[0][j]);
      });
      add("backlash", {cb});
      add("series_compliance", {cs});
    }
    add("sensor_offset", {off});
    add("sensor_gain", {AddJointColumn(pc, w, j, [&](size_t i) { return tau_S[j][i]; })});
    // Time derivative of the predicted reading (for the delay), central differences on the record.
    add("sensor_delay", {AddJointColumn(pc, w, j, [&](size_t i) {
          const size_t a = i == 0 ? 0 : i - 1, c = i + 1 < n ? i + 1 : n - 1;
          return -((tau_S[j][c] - tau_S[j][a]) / (kin.t[c] - kin.t[a]));
        })});
    if (!kin.emg.empty()) {
      std::vector<int> cols;
      std::vector<std::string> chans;
      if (j == 0) {
        // The channels' envelopes two at a time (filtered together: EmgEnvelopes), the pending columns
        // placed first (the envelopes' record-long temporaries come next).
        std::vector<const std::vector<double>*> emg;
        for (const auto& ch : kin.emg) emg.push_back(&ch.second), chans.push_back(ch.first);
        for (size_t c0 = 0; c0 < emg.size(); c0 += 2) {
          pc.Flush();
          const size_t K = std::min<size_t>(2, emg.size() - c0);
          std::vector<std::vector<double>> env = EmgEnvelopes(kin.t, {emg.begin() + static_cast<long>(c0),
                                                                      emg.begin() + static_cast<long>(c0 + K)});
          for (size_t k = 0; k < K; ++k) {
            for (double& v : env[k]) v = -v;
            cols.push_back(NewColumn(b));
            SetJointColumn(pc, cols.back(), w, 0, std::move(env[k]), &envelope_rows[c0 + k]);
          }
        }
      } else {
        for (const auto& ch : kin.emg) {
          const int c = NewColumn(b);
          const std::vector<double>& rows = envelope_rows[chans.size()];
          SetJointRows(b, c, w, j, [&](size_t k) { return rows[k]; });
          cols.push_back(c);
          chans.push_back(ch.first);
        }
      }
      add("muscle_activity", cols)->channels = chans;
    }
    pc.Flush();  // the hip's envelope rows are the knee's
  }
  b.X.conservativeResize(Eigen::NoChange, b.used);
  return b;
}

void AddRippleCandidates(std::vector<ColumnBank>& banks, const std::vector<const Kinematics*>& kins,
                         const std::vector<Eigen::VectorXd>& targets) {
  // The frequency of each joint, searched on the two joints' threads at once (each search reads only).
  double found[2];
  ParallelFor(2, banks[0].threads, [&](size_t jj) {
    const int j = static_cast<int>(jj);
    // The search's rows: at most ~8000 fitting rows per record (every step-th), the angle and the target.
    std::vector<double> q_row, y_row;
    for (size_t r = 0; r < banks.size(); ++r) {
      const ColumnBank& b = banks[r];
      const size_t m = b.sample.size();
      const size_t step = std::max<size_t>(1, m / 8000);
      for (size_t k = 0; k < m; k += step) {
        if (!b.train[k]) continue;
        q_row.push_back(kins[r]->q[j][b.sample[k]]);
        y_row.push_back(targets[r][j * m + k]);
      }
    }
    const size_t N = q_row.size();
    // The rows' phasors exp(i x), x = 2 pi f q, on the grid f = 1, 1.1, .. 10 Hz (dsp::GridPhasors)
    // and at the refinement's frequencies; the residual sum of squares of the target fitted by
    // a sin x + b cos x.
    constexpr int kAnchor = 16;
    dsp::GridPhasors phasors(std::move(q_row), 0.1, kAnchor);
    const std::vector<double>& re = phasors.re();
    const std::vector<double>& im = phasors.im();
    auto sse_of_phasors = [&] {
      double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0, yy = 0;
      for (size_t i = 0; i < N; ++i) {
        const double sn = im[i], c = re[i], y = y_row[i];
        ss += sn * sn, sc += sn * c, cc += c * c, ys += y * sn, yc += y * c, yy += y * y;
      }
      const double det = ss * cc - sc * sc;
      if (det <= 1e-12 * (ss * cc + 1e-300)) return yy;
      const double a = (ys * cc - yc * sc) / det, c2 = (yc * ss - ys * sc) / det;
      return yy - a * ys - c2 * yc;
    };
    auto sse = [&](double f) {
      phasors.At(f);
      return sse_of_phasors();
    };
    double best_f = 1.0, best = 0;
    int g = 0;
    for (double f = 1.0; f <= 10.0 + 1e-9; f += 0.1, ++g) {
      phasors.AtGrid(g, f);
      const double v = sse_of_phasors();
      if (g == 0 || v < best) best = v, best_f = f;
    }
    double lo = best_f - 0.1, hi = best_f + 0.1;
    const double gr = 0.5 * (std::sqrt(5.0) - 1);
    for (int it = 0; it < 24; ++it) {
      const double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo);
      if (sse(x1) < sse(x2)) hi = x2; else lo = x1;
    }
    found[j] = 0.5 * (lo + hi);
  });
  for (int j = 0; j < 2; ++j) {
    const double f = found[j];
    for (size_t r = 0; r < banks.size(); ++r) {
      ColumnBank& b = banks[r];
      const size_t m = b.sample.size();
      // Weight of joint j rows: the offset column of joint j holds exactly w_j there.
      const int off = [&] {
        for (const auto& c : b.candidates)
          if (c.name == "sensor_offset" && c.joint == j) return c.cols[0];
        return -1;
      }();
      const double w = b.X(j * m, off);
      const int c0 = static_cast<int>(b.X.cols());
      b.X.conservativeResize(Eigen::NoChange, c0 + 2);
      b.used = c0 + 2;
      b.X.col(c0).setZero();
      b.X.col(c0 + 1).setZero();
      const size_t n = kins[r]->t.size();
      const double ww[2] = {j == 0 ? w : 0.0, j == 1 ? w : 0.0};
      PendingColumns pc(b);
      std::vector<double> v[2] = {std::vector<double>(n), std::vector<double>(n)};
      ForEachSample(b, n, [&](size_t i) {  // -sin, -cos: joint j's rows (the other joint's are zero)
        const double x = 2 * M_PI * f * kins[r]->q[j][i];
        v[0][i] = -std::sin(x), v[1][i] = -std::cos(x);
      });
      for (int k = 0; k < 2; ++k) SetJointColumn(pc, c0 + k, ww, j, std::move(v[k]));
      pc.Flush();
      Candidate c;
      c.name = "torque_ripple", c.joint = j, c.cols = {c0, c0 + 1}, c.ripple_f = f;
      b.candidates.push_back(c);
    }
  }
}

}  // namespace exotwin
