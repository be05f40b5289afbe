// `exotwin diagnose --fit motion` (motion_fit.h), step 7's spread: each named value's spread across
// resamples of the rows of the fit that produced it, a block bootstrap and fifths left out. The values
// the motion objective moved: one Gauss-Newton step on the final Jacobian; the values step 6b held at
// the torque fit's: that fit's least squares on its candidate columns.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "core/rng.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/motion_fit.h"
#include "diagnosis/motion_fit_internal.h"

namespace exotwin {
namespace motion {

BlockGrams::BlockGrams(size_t blocks, Eigen::Index p)
    : A(blocks, Eigen::MatrixXd::Zero(p, p)), As(5, Eigen::MatrixXd::Zero(p, p)),
      g(blocks, Eigen::VectorXd::Zero(p)), gs(5, Eigen::VectorXd::Zero(p)) {}

void BlockGrams::Add(const Eigen::VectorXd& x, double e, size_t b, size_t f) {
  A[b].noalias() += x * x.transpose(), g[b].noalias() += x * e;
  As[f].noalias() += x * x.transpose(), gs[f].noalias() += x * e;
}

void Resample(const BlockGrams& G, size_t n, const ValuesOf& values, std::vector<double>* sd,
              std::vector<double>* lo, std::vector<double>* hi) {
  const Eigen::Index p = G.As[0].rows();
  const size_t blocks = G.A.size();
  auto Solve = [&](const Eigen::MatrixXd& A, const Eigen::VectorXd& g, std::vector<double>* v) {
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
    const Eigen::VectorXd x = ldlt.solve(g);
    return ldlt.info() == Eigen::Success && x.allFinite() && values(x, v);
  };
  sd->assign(n, NAN), lo->assign(n, NAN), hi->assign(n, NAN);
  std::vector<double> sum(n, 0), sum2(n, 0), v;
  int draws = 0;
  Rng rng(kSpreadSeed);
  for (int b = 0; b < kSpreadBootstraps && blocks > 0; ++b) {
    Eigen::MatrixXd Ar = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd gr = Eigen::VectorXd::Zero(p);
    for (size_t k = 0; k < blocks; ++k) {
      const size_t pick = static_cast<size_t>(rng.Index(static_cast<int>(blocks)));
      Ar += G.A[pick], gr += G.g[pick];
    }
    if (!Solve(Ar, gr, &v)) continue;
    ++draws;
    for (size_t k = 0; k < n; ++k) sum[k] += v[k], sum2[k] += v[k] * v[k];
  }
  if (draws >= 2)
    for (size_t k = 0; k < n; ++k) {
      const double mean = sum[k] / draws;
      (*sd)[k] = std::sqrt(std::max(0.0, (sum2[k] - draws * mean * mean) / (draws - 1)));
    }
  Eigen::MatrixXd At = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd gt = Eigen::VectorXd::Zero(p);
  for (size_t s = 0; s < 5; ++s) At += G.As[s], gt += G.gs[s];
  for (size_t s = 0; s < 5; ++s)
    if (Solve(At - G.As[s], gt - G.gs[s], &v))
      for (size_t k = 0; k < n; ++k)
        (*lo)[k] = std::fmin((*lo)[k], v[k]), (*hi)[k] = std::fmax((*hi)[k], v[k]);
}

bool MotionFit::Held(int c) const {
  const std::vector<int>& kc = cands[static_cast<size_t>(c)].cols;
  return !kc.empty() &&
         std::all_of(kc.begin(), kc.end(), [&](int k) { return std::find(held.begin(), held.end(), k) != held.end(); });
}

void MotionFit::Spread() {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  // The parameters the motion objective moved (not those step 6b held), their final Jacobian columns.
  std::vector<int> fcols;
  std::vector<Eigen::Index> fpos;
  for (size_t c = 0; c < cols.size(); ++c)
    if (std::find(held.begin(), held.end(), cols[c]) == held.end())
      fcols.push_back(cols[c]), fpos.push_back(static_cast<Eigen::Index>(c));
  const Eigen::Index p = static_cast<Eigen::Index>(fcols.size());
  if (p == 0 || last.J.rows() != static_cast<Eigen::Index>(idx.size()) || last.e.size() != last.J.rows() ||
      last.J.cols() != static_cast<Eigen::Index>(cols.size()))
    return;
  // Each fit row's block (a window's rows of one record, both joints alike) and fifth of its record.
  const size_t block_rows = static_cast<size_t>(std::max(1.0, std::round(window_rows)));
  std::vector<size_t> block(idx.size()), fifth(idx.size());
  size_t blocks = 0;
  {
    Eigen::Index off = 0;
    size_t rec = 0, base = 0;
    for (size_t i = 0; i < idx.size(); ++i) {
      while (idx[i] >= off + P.measured(rec).size()) {
        base += (P.fit_rows(rec) + block_rows - 1) / block_rows;
        off += P.measured(rec).size(), ++rec;
      }
      const size_t m = P.rows(rec).size(), k = static_cast<size_t>(idx[i] - off) % m;
      block[i] = base + k / block_rows;
      fifth[i] = std::min<size_t>(4, 5 * k / std::max<size_t>(P.fit_rows(rec), 1));
      blocks = std::max(blocks, block[i] + 1);
    }
  }
  BlockGrams G(blocks, p);
  Eigen::VectorXd x(p);
  for (size_t i = 0; i < idx.size(); ++i) {
    const Eigen::Index r = static_cast<Eigen::Index>(i);
    for (Eigen::Index c = 0; c < p; ++c) x[c] = last.J(r, fpos[static_cast<size_t>(c)]);
    G.Add(x, last.e[r], block[i], fifth[i]);
  }
  // The effects' values at theta + the step d.
  auto Values = [&](const Eigen::VectorXd& d, std::vector<double>* v) {
    Eigen::VectorXd t = theta;
    for (Eigen::Index c = 0; c < p; ++c) {
      const int k = fcols[static_cast<size_t>(c)];
      t[k] = std::clamp(theta[k] + d[c], P.lower(k), P.upper(k));
    }
    v->clear();
    for (int ch : chosen) {
      const Candidate& cand = cands[static_cast<size_t>(ch)];
      Eigen::VectorXd coef(static_cast<Eigen::Index>(cand.cols.size()));
      for (size_t i = 0; i < cand.cols.size(); ++i) coef[static_cast<Eigen::Index>(i)] = t[cand.cols[i]];
      v->push_back(ToEffect(cand, coef, cand.cols).effect.value);
    }
    return true;
  };
  std::vector<double> sd, lo, hi;
  Resample(G, chosen.size(), Values, &sd, &lo, &hi);
  for (size_t k = 0; k < chosen.size() && k < D.effects.size(); ++k) {
    if (Held(chosen[k])) continue;
    D.effects[k].spread_sd = sd[k], D.effects[k].spread_lo = lo[k], D.effects[k].spread_hi = hi[k];
  }
}

void MotionFit::TorqueFitSpread() {
  // The chosen effects step 6b held: the torque fit's effects of the same name, joint and axis.
  std::vector<size_t> at_held;
  for (size_t k = 0; k < chosen.size() && k < D.effects.size(); ++k)
    if (Held(chosen[k])) at_held.push_back(k);
  if (at_held.empty() || records.empty()) return;
  // Each record as the torque fit's stage 2 prepares it (its cutoff), its candidate columns weighted
  // by 1 / the torque fit's noise (diagnose.cc stages 2-3).
  double w[2];
  for (int j = 0; j < 2; ++j) w[j] = T.noise[j] > 0 ? 1 / T.noise[j] : 0.0;
  const int threads = DiagnoseThreads(opt);
  std::vector<ColumnBank> banks;
  std::vector<size_t> windows;  // blocks per record: the motion fit's windows on its fit part
  for (size_t r = 0; r < records.size(); ++r) {
    torque_fit::Rec rc;
    torque_fit::PrepareRecord(params, *records[r], nullptr, T.cutoff, opt.holdout_fraction, threads, &rc);
    banks.push_back(BuildColumns(params, rc.kin, rc.tau_S, rc.resid, w, rc.split,
                                 std::max<size_t>(2000, opt.max_fit_rows / records.size()), rc.FilterFn(), threads));
    windows.push_back(std::max<size_t>(1, P.windows(r, Part::kFit)));
  }
  // The torque fit's named effects among the candidates (searched ripples and terms are not: left out).
  const std::vector<Candidate>& bc = banks[0].candidates;
  std::vector<int> tc, tcols;  // candidates, their columns
  for (const DiagnosedEffect& d : T.effects)
    for (size_t c = 0; c < bc.size(); ++c)
      if (bc[c].name == d.effect.name && kJoint[bc[c].joint] == d.effect.joint && bc[c].axis == d.effect.axis &&
          std::find(tc.begin(), tc.end(), static_cast<int>(c)) == tc.end()) {
        tc.push_back(static_cast<int>(c));
        tcols.insert(tcols.end(), bc[c].cols.begin(), bc[c].cols.end());
      }
  const Eigen::Index p = static_cast<Eigen::Index>(tcols.size());
  if (p == 0) return;
  size_t blocks = 0;
  for (size_t b : windows) blocks += b;
  BlockGrams G(blocks, p);
  Eigen::VectorXd x(p);
  size_t base = 0;
  for (size_t r = 0; r < banks.size(); ++r) {
    const ColumnBank& B = banks[r];
    const size_t m = B.sample.size();
    size_t train = 0, seen = 0;
    for (size_t i = 0; i < m; ++i) train += B.train[i];
    for (size_t i = 0; i < m; ++i) {
      if (!B.train[i]) continue;
      const size_t b = base + std::min(windows[r] - 1, windows[r] * seen / train), f = std::min<size_t>(4, 5 * seen / train);
      ++seen;
      for (size_t j = 0; j < 2; ++j) {
        const Eigen::Index row = static_cast<Eigen::Index>(j * m + i);
        for (Eigen::Index c = 0; c < p; ++c) x[c] = B.X(row, tcols[static_cast<size_t>(c)]);
        G.Add(x, B.r[row], b, f);
      }
    }
    base += windows[r];
  }
  // Each held effect's value from the coefficients of its candidate's columns.
  std::vector<int> of_held;  // per held effect: its candidate in bc (-1: none)
  for (size_t k : at_held) {
    const DiagnosedEffect& d = D.effects[k];
    int found = -1;
    for (int c : tc)
      if (bc[static_cast<size_t>(c)].name == d.effect.name && kJoint[bc[static_cast<size_t>(c)].joint] == d.effect.joint &&
          bc[static_cast<size_t>(c)].axis == d.effect.axis)
        found = c;
    of_held.push_back(found);
  }
  auto Values = [&](const Eigen::VectorXd& beta, std::vector<double>* v) {
    v->clear();
    for (int c : of_held) {
      if (c < 0) {
        v->push_back(NAN);
        continue;
      }
      const Candidate& cand = bc[static_cast<size_t>(c)];
      Eigen::VectorXd coef(static_cast<Eigen::Index>(cand.cols.size()));
      for (size_t i = 0; i < cand.cols.size(); ++i)
        coef[static_cast<Eigen::Index>(i)] =
            beta[std::find(tcols.begin(), tcols.end(), cand.cols[i]) - tcols.begin()];
      v->push_back(ToEffect(cand, coef, cand.cols).effect.value);
    }
    return true;
  };
  // The full rows' values, the resamples' offsets from them added to the values reported.
  Eigen::MatrixXd At = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd gt = Eigen::VectorXd::Zero(p);
  for (size_t s = 0; s < 5; ++s) At += G.As[s], gt += G.gs[s];
  std::vector<double> full, sd, lo, hi;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(At);
  if (ldlt.info() != Eigen::Success || !Values(ldlt.solve(gt), &full)) return;
  Resample(G, of_held.size(), Values, &sd, &lo, &hi);
  for (size_t h = 0; h < at_held.size(); ++h) {
    DiagnosedEffect& d = D.effects[at_held[h]];
    if (!std::isfinite(full[h])) continue;
    d.spread_sd = sd[h];
    d.spread_lo = d.effect.value + (lo[h] - full[h]), d.spread_hi = d.effect.value + (hi[h] - full[h]);
  }
}

}  // namespace motion
}  // namespace exotwin
