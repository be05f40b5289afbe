// The torque fit's stages (diagnose.cc) that ask the families' fit rows: the secant columns (stage
// 3b), the range edge of a candidate, and the extension with its refinement (stage 5).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "diagnosis/fit_families.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/effects.h"
#include "formats/measured_data.h"

namespace exotwin {
namespace torque_fit {

namespace {

// Weighted SSE of the filtered (measured - (base tau_R through ApplyEffects(p))) on samples [a, b).
double ExactSse(const LegParams& p, const Rec& rc, const double w[2], size_t a, size_t b) {
  if (b <= a + 2) return 0;
  const Kinematics& kin = rc.kin;
  Kinematics k;
  k.t.assign(kin.t.begin() + a, kin.t.begin() + b);
  std::vector<double> tr[2], ts[2];
  for (int j = 0; j < 2; ++j) {
    k.q[j].assign(kin.q[j].begin() + a, kin.q[j].begin() + b);
    k.qd[j].assign(kin.qd[j].begin() + a, kin.qd[j].begin() + b);
    k.qdd[j].assign(kin.qdd[j].begin() + a, kin.qdd[j].begin() + b);
    tr[j].assign(rc.tau_R[j].begin() + a, rc.tau_R[j].begin() + b);
  }
  for (const auto& ch : kin.emg) k.emg[ch.first].assign(ch.second.begin() + a, ch.second.begin() + b);
  k.t_start = kin.t_start;
  ApplyEffects(p, k, tr, ts);
  double s = 0;
  const size_t lo = std::min<size_t>(200, (b - a) / 10);  // skip the edges (delay, filters)
  for (int j = 0; j < 2; ++j) {
    std::vector<double> e(b - a);
    for (size_t i = 0; i < b - a; ++i) e[i] = rc.raw[j][a + i] - ts[j][i];
    e = rc.Filter(std::move(e), a);
    for (size_t i = lo; i + lo < b - a; ++i) s += std::pow(w[j] * e[i], 2);
  }
  return s;
}

}  // namespace

void UseSecantColumns(const std::vector<Rec>& recs, const double w[2], std::vector<ColumnBank>* banks_io) {
  std::vector<ColumnBank>& banks = *banks_io;
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& c : banks[0].candidates) {
      const FitFamily& ff = FitFamilyOf(c.name);
      if (!ff.secant_column) continue;
      const int j = c.joint;
      double xr = 0, xx = 0;
      for (const ColumnBank& b : banks) {
        const size_t m = b.sample.size();
        for (size_t k = 0; k < m; ++k) {
          if (!b.train[k]) continue;
          const double x = b.X(j * m + k, c.cols[0]);
          xr += x * b.r[j * m + k], xx += x * x;
        }
      }
      const double d = xx > 0 ? xr / xx : 0;
      for (size_t r = 0; r < recs.size(); ++r) {
        const Rec& rc = recs[r];
        std::vector<double> v[2] = {std::vector<double>(rc.n(), 0.0), std::vector<double>(rc.n(), 0.0)};
        if (!ff.secant_column(d, rc.kin, rc.tau_S[j], &v[j])) break;  // d not taken: no record changed
        SetColumn(banks[r], c.cols[0], w, v);
      }
    }
  }
}

double RangeEdge(const Candidate& c, const PhysicalScale& s) {
  const FitFamily& f = FitFamilyOf(c.name);
  return f.range_edge ? f.range_edge(c.joint, s) : 0.0;
}

size_t RefineRows(const Rec& rc, size_t R) { return std::min<size_t>(rc.split, 6000 / R + 1); }

std::vector<double> ExtendAndRefine(const LegParams& params, const std::vector<Rec>& recs, const double w[2],
                                    const ColumnBank& bank, const Grams& g, const Fit& f0,
                                    const std::vector<int>& chosen, const Fit& chosen_fit, Diagnosis* D) {
  const size_t R = recs.size();
  D->extended = params;
  std::vector<double> refine_ratio(chosen.size(), 1.0);
  for (int c : chosen) D->effects.push_back(ToEffect(bank.candidates[c], chosen_fit));
  for (auto& de : D->effects) D->extended.effects.push_back(de.effect);
  for (size_t k = 0; k < D->effects.size(); ++k) {
    if (!FitFamilyOf(D->effects[k].effect.name).refined_on_exact_form) continue;
    const size_t idx = params.effects.size() + k;
    const double v0 = D->extended.effects[idx].value;
    auto obj = [&](double v) {
      LegParams p = D->extended;
      p.effects[idx].value = v;
      double s = 0;
      for (const Rec& rc : recs) s += ExactSse(p, rc, w, 0, RefineRows(rc, R));
      return s;
    };
    double lo = 0.6 * v0, hi = 1.6 * v0;
    const double gr = 0.5 * (std::sqrt(5.0) - 1);
    double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo), f1 = obj(x1), f2 = obj(x2);
    for (int it = 0; it < 16; ++it) {
      if (f1 < f2) hi = x2, x2 = x1, f2 = f1, x1 = hi - gr * (hi - lo), f1 = obj(x1);
      else lo = x1, x1 = x2, f1 = f2, x2 = lo + gr * (hi - lo), f2 = obj(x2);
    }
    const double v = 0.5 * (lo + hi);
    refine_ratio[k] = v / v0;
    D->extended.effects[idx].value = v;
    D->effects[k].effect.value = v;
    D->effects[k].ci_lo *= v / v0, D->effects[k].ci_hi *= v / v0;
  }
  // Share of the held-out residual each effect removes (joint linear model, leave-one-effect-out).
  for (size_t k = 0; k < chosen.size(); ++k) {
    std::vector<int> rest = chosen;
    rest.erase(rest.begin() + static_cast<long>(k));
    const Fit fr = FitCols(g, ColumnsOf(bank, rest));
    D->effects[k].explained_pct = f0.sse_te > 0 ? 100 * (fr.sse_te - chosen_fit.sse_te) / f0.sse_te : 0;
  }
  return refine_ratio;
}

}  // namespace torque_fit
}  // namespace exotwin
