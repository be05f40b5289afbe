// The tools that put a candidate's columns into a ColumnBank (diagnose_columns.h): new columns,
// per-sample values evaluated on the machine's cores, the bank's low-pass in groups (PendingColumns),
// the weighted fit rows; and ColumnContext, what a family's column builder sees at one joint
// (FitFamily::add_columns). Shared by diagnose_columns.cc and the families' files (family_*.cc).
#pragma once
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "core/parallel_for.h"
#include "diagnosis/diagnose_columns.h"

namespace exotwin {

struct FitFamily;

inline constexpr size_t kPendingColumns = 4;  // PendingColumns::kPending, and SetColumn's two

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
inline int NewColumn(ColumnBank& b) {
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
inline void PlaceJointRows(ColumnBank& b, int c, const double w[2], int j, const std::vector<double>& x) {
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
inline void SetJointColumn(PendingColumns& p, int c, const double w[2], int j, std::vector<double> x,
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

// What a family's torque-fit column builder (FitFamily::add_columns) sees at joint j: the bank with its
// pending columns, the twin, the record, the row weights and the joint's constant column (1 on its
// rows: the sensor offset's column and the stiffness's constant part). One context serves both joints
// of a record in turn (hip, then knee), so a family may keep the hip's rows for the knee's.
struct ColumnContext {
  ColumnBank& bank;
  PendingColumns& pending;
  const LegParams& params;        // the twin as given (with its effects)
  const LegParams& rigid;         // the same without effects
  const LumpedParams& total;      // rigid.Total()
  const Kinematics& kin;
  const std::vector<double>* tau_S;  // [2] the twin's predicted reading on every sample
  const double* w;                   // [2] row weights
  int j = 0;
  int constant = -1;
  std::vector<std::vector<double>> kept_rows;  // rows a family keeps from the hip for the knee

  size_t n() const { return kin.t.size(); }
  // Appends the candidate of family f at joint j on columns cols.
  Candidate& AddCandidate(const FitFamily& f, std::vector<int> cols, const std::string& axis = "");
};

}  // namespace exotwin
