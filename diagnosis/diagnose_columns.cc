#include "diagnosis/diagnose_columns.h"

#include <algorithm>
#include <cmath>

#include "core/parallel_for.h"
#include "diagnosis/column_tools.h"
#include "diagnosis/fit_families.h"

namespace exotwin {

std::string Candidate::Label() const {
  return name + (axis.empty() ? "" : "." + axis) + (joint == 0 ? "(hip)" : "(knee)");
}

namespace {

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
  PendingColumns pc(b);
  ColumnContext ctx{b, pc, params, rigid, total, kin, tau_S, w};
  // A first allocation of the columns (NewColumn grows X where more are needed): per joint the
  // constant, the families' columns (about 16) and one per EMG channel.
  b.X.resize(2 * m, 2 * (16 + static_cast<long>(kin.emg.size())));
  for (int j = 0; j < 2; ++j) {
    ctx.j = j;
    ctx.constant = b.constant[j] = AddJointColumn(pc, w, j, [&](size_t) { return 1.0; });
    // The families linear in their value (FitFamily::linear_column): -link_torque at value 1.
    for (const FitFamily& ff : FitFamilies()) {
      if (!ff.linear_column || (ff.candidate_for && !ff.candidate_for(params))) continue;
      for (const std::string& axis : ff.axes.empty() ? std::vector<std::string>{""} : ff.axes) {
        Effect unit;
        unit.name = ff.family->name, unit.joint = j == 0 ? "hip" : "knee", unit.value = 1.0, unit.axis = axis;
        ctx.AddCandidate(ff, {AddLinearColumn(pc, w, j, unit, *ff.family, kin, params.g)}, axis);
      }
    }
    // Then the families with their own columns, in the registry's order.
    for (const FitFamily& ff : FitFamilies())
      if (ff.add_columns && (!ff.candidate_for || ff.candidate_for(params))) ff.add_columns(ctx, ff);
    pc.Flush();  // a family's rows kept from the hip are the knee's
  }
  b.X.conservativeResize(Eigen::NoChange, b.used);
  return b;
}

void AddSearchedCandidates(std::vector<ColumnBank>& banks, const std::vector<const Kinematics*>& kins,
                           const std::vector<Eigen::VectorXd>& targets) {
  for (const FitFamily& ff : FitFamilies())
    if (ff.add_searched_columns) ff.add_searched_columns(banks, kins, targets, ff);
}

Candidate& ColumnContext::AddCandidate(const FitFamily& f, std::vector<int> cols, const std::string& axis) {
  Candidate c;
  c.name = f.family->name, c.joint = j, c.cols = std::move(cols), c.axis = axis;
  bank.candidates.push_back(std::move(c));
  return bank.candidates.back();
}

}  // namespace exotwin
