#include "diagnosis/term_search.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <cstdio>

#include <Eigen/Dense>

#include "diagnosis/diagnose_select.h"
#include "diagnosis/effects.h"
#include "diagnosis/term_library.h"
#include "core/parallel_for.h"
#include "model/effect_families.h"
#include "model/leg_dynamics.h"
#include "model/term_expr.h"

namespace exotwin {
namespace torque_fit {
namespace {

constexpr size_t kScreenRows = 6000;   // train rows per joint the screening takes (strided, pooled)
constexpr double kTableForm = 0.02;    // a column within 2 % of the table's forms' span is theirs
constexpr int kGoldenSteps = 14;

const char* kJointName[2] = {"hip", "knee"};

// One record's material: the rigid actuator torque on every sample, the fit rows' weighted target r0
// (the residual without the table's effects) and the named effects' columns.
struct SearchRec {
  const Rec* rc = nullptr;
  const ColumnBank* bank = nullptr;
  size_t m = 0, mtr = 0;
  std::vector<double> tauR[2];
  Eigen::VectorXd r0;   // 2m
  Eigen::MatrixXd C;    // 2m x K
};

double RecordStart(const Kinematics& k) { return std::isnan(k.t_start) ? k.t.front() : k.t_start; }

TermRow RowAt(const SearchRec& s, int j, size_t i) {
  const Kinematics& k = s.rc->kin;
  const int o = 1 - j;
  return {{k.q[j][i], k.qd[j][i], k.qdd[j][i], s.tauR[j][i], k.q[o][i], k.qd[o][i], k.t[i] - RecordStart(k)}};
}

// The reading of the twin `p` on every sample from the rigid torque.
void Reading(const LegParams& p, const SearchRec& s, std::vector<double> tau_S[2]) {
  std::vector<double> tr[2] = {s.tauR[0], s.tauR[1]};
  ApplyEffects(p, s.rc->kin, tr, tau_S);
}

// Weighted fit rows of a per-sample series pair (hip rows, then knee rows).
Eigen::VectorXd Rows(const SearchRec& s, const std::vector<double> v[2], const double w[2]) {
  Eigen::VectorXd x(2 * s.m);
  for (int j = 0; j < 2; ++j)
    for (size_t k = 0; k < s.m; ++k) x[j * s.m + k] = w[j] * v[j][s.bank->sample[k]];
  return x;
}

SearchRec Prepare(const LegParams& params, const Rec& rc, const ColumnBank& bank, const double w[2],
                  const Diagnosis& D) {
  SearchRec s;
  s.rc = &rc;
  s.bank = &bank;
  s.m = bank.sample.size();
  s.mtr = static_cast<size_t>(std::count(bank.train.begin(), bank.train.end(), true));
  const Kinematics& kin = rc.kin;
  for (int j = 0; j < 2; ++j) s.tauR[j].resize(kin.t.size());
  for (size_t i = 0; i < kin.t.size(); ++i) {
    const Eigen::Vector2d t = ActuatorTorque(params, {kin.q[0][i], kin.q[1][i]}, {kin.qd[0][i], kin.qd[1][i]},
                                             {kin.qdd[0][i], kin.qdd[1][i]});
    s.tauR[0][i] = t[0], s.tauR[1][i] = t[1];
  }
  std::vector<double> ext[2], e[2];
  Reading(D.extended, s, ext);
  for (int j = 0; j < 2; ++j) {
    e[j].resize(kin.t.size());
    for (size_t i = 0; i < e[j].size(); ++i) e[j][i] = rc.raw[j][i] - ext[j][i];
  }
  rc.FilterBoth(e);
  s.r0 = Rows(s, e, w);
  const size_t first = params.effects.size(), K = D.effects.size();
  s.C.resize(2 * static_cast<Eigen::Index>(s.m), static_cast<Eigen::Index>(K));
  for (size_t k = 0; k < K; ++k) {
    LegParams without = D.extended;
    without.effects.erase(without.effects.begin() + static_cast<long>(first + k));
    std::vector<double> wo[2], d[2];
    Reading(without, s, wo);
    const double v = D.effects[k].effect.value;
    for (int j = 0; j < 2; ++j) {
      d[j].resize(kin.t.size());
      for (size_t i = 0; i < d[j].size(); ++i) d[j][i] = (ext[j][i] - wo[j][i]) / v;
    }
    rc.FilterBoth(d);
    s.C.col(static_cast<Eigen::Index>(k)) = Rows(s, d, w);
    s.r0 += v * s.C.col(static_cast<Eigen::Index>(k));
  }
  return s;
}

// The exact column(s) of a candidate at joint j: -expr (a link term's dtau_S / dvalue), filtered as
// the residual, on the fit rows, weighted; zero on the other joint's rows.
Eigen::MatrixXd ExactColumns(const SearchRec& s, int j, const TermCandidate& c, const double w[2]) {
  const int cols = c.Paired() ? 2 : 1;
  const size_t n = s.rc->kin.t.size();
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(2 * static_cast<Eigen::Index>(s.m), cols);
  for (int col = 0; col < cols; ++col) {
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = -CandidateValue(c, RowAt(s, j, i), col == 1);
    v = s.rc->Filter(std::move(v));
    for (size_t k = 0; k < s.m; ++k) X(static_cast<Eigen::Index>(j * s.m + k), col) = w[j] * v[s.bank->sample[k]];
  }
  return X;
}

// The screening rows: a strided subset of every record's train rows, both joints' blocks.
struct Screen {
  std::vector<std::pair<size_t, size_t>> at;  // (record, fit row) of each screening row
  std::vector<TermRow> rows[2];               // each one's signals at each joint (RowAt)
  Eigen::MatrixXd Q;     // 2N x q: orthonormal basis of the current model's columns
  Eigen::VectorXd y;     // 2N: the target with the current model projected out
  Eigen::MatrixXd B[2];  // N x b: orthonormal basis of the table's forms at each joint (unweighted)
  size_t N = 0;
};

// Factors' values on the screening rows of one joint (FactorValue; a kSin factor's sin and its cos),
// by function, signal and inner parameter: a candidate's column is a product of them.
using FactorKey = std::tuple<int, int, double>;
using FactorValues = std::map<FactorKey, std::array<std::vector<double>, 2>>;
FactorKey KeyOf(const TermFactor& f) { return {static_cast<int>(f.fn), static_cast<int>(f.sig), f.p}; }

// The values of every factor of `lib` at joint j, on up to `threads` threads.
FactorValues ValuesOf(const Screen& sc, int j, const std::vector<TermCandidate>& lib, int threads) {
  FactorValues v;
  std::vector<std::pair<TermFactor, std::array<std::vector<double>, 2>*>> todo;
  for (const TermCandidate& c : lib)
    for (const TermFactor& f : c.factors)
      if (!v.count(KeyOf(f))) todo.push_back({f, &v[KeyOf(f)]});
  ParallelFor(todo.size(), threads, [&](size_t i) {
    const TermFactor& f = todo[i].first;
    for (int cosine = 0; cosine < (f.fn == TermFn::kSin ? 2 : 1); ++cosine) {
      std::vector<double>& x = (*todo[i].second)[static_cast<size_t>(cosine)];
      x.resize(sc.N);
      for (size_t k = 0; k < sc.N; ++k) x[k] = FactorValue(f, sc.rows[j][k], cosine == 1);
    }
  });
  return v;
}

// The candidate's values on the screening rows of joint j (-expr, weighted, unfiltered): the product
// of its factors' (CandidateValue's), from `known` where it holds them.
Eigen::MatrixXd ScreenColumns(const Screen& sc, int j, const TermCandidate& c, const double w[2],
                              const FactorValues* known = nullptr) {
  Eigen::MatrixXd x(static_cast<Eigen::Index>(sc.N), c.Paired() ? 2 : 1);
  for (Eigen::Index col = 0; col < x.cols(); ++col) {
    std::vector<const std::vector<double>*> f;
    std::vector<std::vector<double>> own;
    own.reserve(c.factors.size());
    for (const TermFactor& fa : c.factors) {
      const size_t which = col == 1 && fa.fn == TermFn::kSin ? 1 : 0;
      const auto it = known ? known->find(KeyOf(fa)) : FactorValues::const_iterator();
      if (known && it != known->end()) {
        f.push_back(&it->second[which]);
        continue;
      }
      own.emplace_back(sc.N);
      for (size_t k = 0; k < sc.N; ++k) own.back()[k] = FactorValue(fa, sc.rows[j][k], col == 1);
      f.push_back(&own.back());
    }
    for (size_t k = 0; k < sc.N; ++k) {
      double v = 1;
      for (const std::vector<double>* fv : f) v *= (*fv)[k];
      x(static_cast<Eigen::Index>(k), col) = -w[j] * v;
    }
  }
  return x;
}

// The drop of the screening rows' error a candidate brings beside the current model (0: an alias of
// the model or a table form).
double ScreenGain(const Screen& sc, int j, const Eigen::MatrixXd& x) {
  const Eigen::Index N = static_cast<Eigen::Index>(sc.N);
  const auto Qj = sc.Q.middleRows(j * N, N);
  const Eigen::MatrixXd QtX = Qj.transpose() * x;
  Eigen::MatrixXd G = x.transpose() * x - QtX.transpose() * QtX;
  const Eigen::VectorXd c = x.transpose() * sc.y.segment(j * N, N);
  for (Eigen::Index a = 0; a < x.cols(); ++a) {
    const double xx = x.col(a).squaredNorm();
    if (!(xx > 0) || G(a, a) < 0.05 * xx) return 0;  // nearly in the current model's span
    const double tf = (sc.B[j].transpose() * x.col(a)).squaredNorm();
    if (xx - tf < kTableForm * xx) return 0;          // a form of the table
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(G);
  if (ldlt.info() != Eigen::Success) return 0;
  const double g = c.dot(ldlt.solve(c));
  return std::isfinite(g) ? g : 0;
}

Screen MakeScreen(const std::vector<SearchRec>& S, const Eigen::MatrixXd& Zrows, const Eigen::VectorXd& yrows,
                  const std::vector<std::pair<size_t, size_t>>& at, const double w[2]) {
  Screen sc;
  sc.at = at;
  sc.N = at.size();
  const Eigen::Index N = static_cast<Eigen::Index>(sc.N);
  if (Zrows.cols() > 0) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(Zrows);
    sc.Q = qr.householderQ() * Eigen::MatrixXd::Identity(Zrows.rows(), Zrows.cols());
  } else {
    sc.Q = Eigen::MatrixXd::Zero(2 * N, 0);
  }
  sc.y = yrows - sc.Q * (sc.Q.transpose() * yrows);
  // The table's forms at a joint: 1, q, qd, sgn(qd), qdd and tau_R (offset, stiffness, viscous and
  // Coulomb friction, inertia, gain): a term is a form the table does not have.
  for (int j = 0; j < 2; ++j) {
    Eigen::MatrixXd B(N, 6);
    sc.rows[j].resize(sc.N);
    for (Eigen::Index k = 0; k < N; ++k) {
      const SearchRec& s = S[at[k].first];
      const TermRow r = sc.rows[j][static_cast<size_t>(k)] = RowAt(s, j, s.bank->sample[at[k].second]);
      const double qd = r.s[1];
      B.row(k) << w[j], w[j] * r.s[0], w[j] * qd, w[j] * (qd > 0 ? 1.0 : (qd < 0 ? -1.0 : 0.0)), w[j] * r.s[2],
          w[j] * r.s[3];
    }
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(B);
    sc.B[j] = qr.householderQ() * Eigen::MatrixXd::Identity(N, 6);
  }
  return sc;
}


// A candidate's shape: its functions and signals (the inner parameters left out).
std::vector<std::pair<int, int>> ShapeOf(const TermCandidate& c) {
  std::vector<std::pair<int, int>> k;
  for (const TermFactor& f : c.factors) k.push_back({static_cast<int>(f.fn), static_cast<int>(f.sig)});
  return k;
}

struct Scored {
  int joint = 0;
  TermCandidate c;
  double gain = 0;
};

// The best of every shape on the screening rows, its inner parameter refined by golden search on
// log p between its grid neighbours; best first. *screened counts the candidates evaluated. The
// candidates' gains, then the shapes' refinements, on up to `threads` threads (the same result on any
// count: each is a function of its candidate alone, gathered in the library's order).
std::vector<Scored> ScreenAll(const std::vector<SearchRec>& S, const Screen& sc, const double w[2], bool two_joints,
                              const std::vector<int>& joints, int threads, size_t* screened) {
  using Key = std::pair<int, std::vector<std::pair<int, int>>>;
  std::map<Key, Scored> best;
  std::map<Key, TermScales> scales_of;
  FactorValues values[2];
  for (int j : joints) {
    TermScales ts;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300}, qd2 = 0, cnt = 0;
    for (const SearchRec& s : S) {
      const Kinematics& k = s.rc->kin;
      ts.duration = std::max(ts.duration, k.t.back() - RecordStart(k));
      for (size_t i = 0; i < k.t.size(); i += 10) {
        for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], k.q[a][i]), hi[a] = std::max(hi[a], k.q[a][i]);
        qd2 += k.qd[j][i] * k.qd[j][i], cnt += 1;
      }
    }
    ts.qd_rms = std::max(1e-3, std::sqrt(qd2 / std::max(cnt, 1.0)));
    ts.q_range = std::max(0.05, hi[j] - lo[j]);
    ts.q_other_range = std::max(0.05, hi[1 - j] - lo[1 - j]);
    const std::vector<TermCandidate> lib = TermLibrary(ts, two_joints);
    values[j] = ValuesOf(sc, j, lib, threads);
    std::vector<double> gains(lib.size());
    ParallelFor(lib.size(), threads, [&](size_t i) { gains[i] = ScreenGain(sc, j, ScreenColumns(sc, j, lib[i], w, &values[j])); });
    for (size_t i = 0; i < lib.size(); ++i) {
      ++*screened;
      const Key key = std::make_pair(j, ShapeOf(lib[i]));
      scales_of[key] = ts;
      if (gains[i] > best[key].gain) best[key] = {j, lib[i], gains[i]};
    }
  }
  std::vector<std::pair<Scored, TermScales>> shapes;
  for (auto& kv : best)
    if (kv.second.gain > 0) shapes.push_back({kv.second, scales_of[kv.first]});
  ParallelFor(shapes.size(), threads, [&](size_t k) {
    Scored& sd = shapes[k].first;
    for (TermFactor& f : sd.c.factors) {
      const std::vector<double> grid = InnerGrid(f.fn, shapes[k].second);
      if (grid.empty()) continue;
      const size_t at = static_cast<size_t>(std::find(grid.begin(), grid.end(), f.p) - grid.begin());
      double a = std::log(grid[at == 0 ? 0 : at - 1]), b = std::log(grid[std::min(at + 1, grid.size() - 1)]);
      auto gain = [&](double lp) {
        TermCandidate c = sd.c;
        for (TermFactor& g : c.factors)
          if (g.fn == f.fn && g.sig == f.sig) g.p = RoundedInner(std::exp(lp));
        return ScreenGain(sc, sd.joint, ScreenColumns(sc, sd.joint, c, w, &values[sd.joint]));
      };
      const double gr = 0.5 * (std::sqrt(5.0) - 1);
      double x1 = b - gr * (b - a), x2 = a + gr * (b - a), g1 = gain(x1), g2 = gain(x2);
      for (int it = 0; it < kGoldenSteps; ++it) {
        if (g1 > g2) b = x2, x2 = x1, g2 = g1, x1 = b - gr * (b - a), g1 = gain(x1);
        else a = x1, x1 = x2, g1 = g2, x2 = a + gr * (b - a), g2 = gain(x2);
      }
      const double lp = g1 > g2 ? x1 : x2;
      if (std::max(g1, g2) > sd.gain) {
        f.p = RoundedInner(std::exp(lp));
        sd.gain = std::max(g1, g2);
      }
    }
  });
  std::vector<Scored> out;
  for (auto& sh : shapes) out.push_back(sh.first);
  std::sort(out.begin(), out.end(), [](const Scored& a, const Scored& b) { return a.gain > b.gain; });
  return out;
}

// The table's link forms at the term's joint, as candidates: q (stiffness), qd (viscous friction),
// sgn(qd) (Coulomb friction), qdd (inertia), tau_R (a gain).
// The table's forms that compete with a term at its joint: a stiffness (q), viscous and Coulomb
// friction (qd, sgn(qd)), an inertia error (qdd) and a sensor gain (tau_R). `passive`: the table names
// the form only with a positive coefficient (a restoring or dissipative torque, which the actuator's
// tau_R grows by); at the other sign it is no table effect, so it takes no term's place.
struct TableForm {
  TermCandidate c;
  bool passive = false;
};
const std::vector<TableForm>& TableForms() {
  using S = TermSignal;
  static const std::vector<TableForm> k = {{{{{TermFn::kId, S::kQ, 0}}}, true},
                                           {{{{TermFn::kId, S::kQd, 0}}}, true},
                                           {{{{TermFn::kSgn, S::kQd, 0}}}, true},
                                           {{{{TermFn::kId, S::kQdd, 0}}}, false},
                                           {{{{TermFn::kId, S::kTauR, 0}}}, false}};
  return k;
}

// A term in the model: its joint, candidate and columns in the banks.
struct Term {
  int joint = 0;
  TermCandidate c;
  std::vector<int> cols;
};

// The banks of the model's columns (the table's K, then the terms') plus `extra` columns per record.
Grams MakeSearchGrams(const std::vector<SearchRec>& S, const std::vector<Eigen::MatrixXd>& model_cols,
                      const std::vector<Eigen::MatrixXd>& extra, const double w[2], double tau_eff) {
  std::vector<ColumnBank> banks(S.size());
  for (size_t r = 0; r < S.size(); ++r) {
    ColumnBank& b = banks[r];
    b.sample = S[r].bank->sample;
    b.train = S[r].bank->train;
    b.X.resize(model_cols[r].rows(), model_cols[r].cols() + extra[r].cols());
    b.X << model_cols[r], extra[r];
    b.r = S[r].r0;
    b.used = static_cast<int>(b.X.cols());
  }
  Grams g = MakeGrams(banks);
  g.n_eff = g.n_tr / std::max(1.0, tau_eff);
  for (size_t r = 0; r < S.size(); ++r)
    for (size_t k = S[r].mtr; k < S[r].m; ++k)
      for (int j = 0; j < 2; ++j) g.tt_te[j] += std::pow(w[j] * S[r].rc->meas[j][S[r].bank->sample[k]], 2);
  return g;
}

// |coefficient| / standard error of a term's columns (a pair: its amplitude's).
double TermT(const Fit& f, const std::vector<int>& cols) {
  double a2 = 0, v = 0;
  for (int c : cols) {
    const double x = CoefOf(f, c), se = SeOf(f, c);
    a2 += x * x, v += x * x * se * se;
  }
  if (!(a2 > 0)) return 0;
  return std::sqrt(a2) / std::max(1e-300, std::sqrt(v / a2));
}

std::vector<int> Without(std::vector<int> v, const std::vector<int>& drop) {
  v.erase(std::remove_if(v.begin(), v.end(), [&](int c) { return std::count(drop.begin(), drop.end(), c) > 0; }),
          v.end());
  return v;
}

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

// The term's effect from coefficients `coef` of `cols` (a pair: amplitude and phase).
DiagnosedEffect TermEffect(const Term& t, const Eigen::VectorXd& coef, const std::vector<int>& cols,
                           const Fit* f) {
  auto at = [&](int c) {
    return coef[static_cast<Eigen::Index>(std::find(cols.begin(), cols.end(), c) - cols.begin())];
  };
  DiagnosedEffect d;
  d.effect.name = kTerm;
  d.effect.joint = kJointName[t.joint];
  d.effect.unit = "N m";
  double phi = 0, se = 0;
  if (t.cols.size() == 2) {
    const double a = at(t.cols[0]), b = at(t.cols[1]);
    d.effect.value = std::hypot(a, b);
    phi = std::atan2(b, a);
  } else {
    d.effect.value = at(t.cols[0]);
  }
  if (f) se = d.effect.value == 0 ? 0 : std::abs(d.effect.value) / std::max(1e-300, TermT(*f, t.cols));
  d.effect.expr = CandidateExpr(t.c, d.effect.joint, phi);
  d.ci_lo = d.effect.value - 1.96 * se, d.ci_hi = d.effect.value + 1.96 * se;
  return d;
}

// A candidate that acts only near rest at its joint: an even function of the joint's velocity that
// vanishes with speed (every factor of qd a exp(-(qd / v)^2), at least one). Where a Coulomb friction
// is named at the joint, such a torque is that friction's sticking phase, whose torque is set-valued
// (any value within its bound: the plant's friction constraint, a real drive's static friction), not
// a law of the motion: no term.
bool StickPhase(const TermCandidate& c) {
  bool gauss = false;
  for (const TermFactor& f : c.factors)
    if (f.sig == TermSignal::kQd) {
      if (f.fn != TermFn::kGauss) return false;
      gauss = true;
    }
  return gauss;
}

// Whether a Coulomb friction of the table at joint j is in the current model (its column in `cur`).
bool CoulombNamed(const Diagnosis& D, const std::vector<int>& cur, int j) {
  for (int c : cur)
    if (c < static_cast<int>(D.effects.size()) && D.effects[static_cast<size_t>(c)].effect.name == kCoulombFriction &&
        EffectJoint(D.effects[static_cast<size_t>(c)].effect) == j)
      return true;
  return false;
}

// Backward elimination: drops, one at a time, the table effect (columns below K of `cur`) that no
// longer earns the BIC margin or |t| beside the terms and whose absence costs its joint's held-out
// error less than the selection's gates (kMinHeldoutGain of it or the material floor; tt_te: the
// measured torque's weighted sum of squares on the held-out rows), or that left its physical range.
void DropRedundant(const std::vector<SearchRec>& S, const std::vector<Eigen::MatrixXd>& model, const double w[2],
                   const PhysicalScale& scale, size_t K, const double tt_te[2], Diagnosis* D,
                   std::vector<int>* cur_out) {
  std::vector<int>& cur = *cur_out;
  const size_t R = S.size();
  const std::vector<Eigen::MatrixXd> none(R, Eigen::MatrixXd(model[0].rows(), 0));
  const Grams gm = MakeSearchGrams(S, model, none, w, D->tau_eff);
  for (;;) {
    const Fit f = FitCols(gm, cur);
    int drop = -1;
    double least = 1e300;
    for (int c : cur) {
      if (c >= static_cast<int>(K)) continue;
      const Fit fk = FitCols(gm, Without(cur, {c}));
      const double loss = fk.bic - f.bic, tk = std::abs(CoefOf(f, c)) / std::max(1e-300, SeOf(f, c));
      DiagnosedEffect de = D->effects[static_cast<size_t>(c)];
      de.effect.value = CoefOf(f, c);
      // Redundant: it no longer earns the BIC margin or |t| and leaving it out costs its joint's
      // held-out error less than the selection's gates ask of an effect, kMinHeldoutGain of it or
      // the material floor (kMinTorqueShare of the measured torque's RMS, squared, on those rows): a
      // term that only resembles it keeps it; or out of its range.
      const int jc = EffectJoint(de.effect);
      const double cost = fk.sse_te_j[jc] - f.sse_te_j[jc];
      const bool held = cost < kMinHeldoutGain * f.sse_te_j[jc] || cost < kMinTorqueShare * kMinTorqueShare * tt_te[jc];
      const bool redundant = (loss < kBicMargin || tk < kMinT) && held;
      if ((redundant || !Plausible(de, scale)) && loss < least) least = loss, drop = c;
    }
    if (drop < 0) break;
    D->term_search.push_back("dropped " + D->effects[static_cast<size_t>(drop)].effect.name + " (" +
                             D->effects[static_cast<size_t>(drop)].effect.joint + "): redundant beside the terms");
    cur = Without(cur, {drop});
  }
}

// The named terms' component-plus-residual plots on the first record's fit rows (diagnose.h TermPlot):
// the residual of the final fit `f` on `model` plus each term's own fitted columns.
std::vector<TermPlot> TermPlots(const SearchRec& s, const Eigen::MatrixXd& model, const Fit& f,
                                const std::vector<Term>& terms, const std::vector<DiagnosedEffect>& effects,
                                const double w[2]) {
  static const char* kSignal[2] = {"q", "qd"};
  std::vector<TermPlot> out;
  Eigen::VectorXd fitted = Eigen::VectorXd::Zero(s.r0.size());
  for (size_t c = 0; c < f.cols.size(); ++c) fitted += f.coef[static_cast<Eigen::Index>(c)] * model.col(f.cols[c]);
  const Eigen::VectorXd resid = s.r0 - fitted;
  const size_t stride = std::max<size_t>(1, (s.m + kTermPlotPoints - 1) / kTermPlotPoints);
  size_t e = 0;
  for (const Term& t : terms) {
    while (e < effects.size() && effects[e].effect.name != kTerm) ++e;
    const DiagnosedEffect& de = effects[e++];
    TermPlot p;
    p.joint = de.effect.joint, p.expr = de.effect.expr, p.value = de.effect.value;
    Eigen::VectorXd own = Eigen::VectorXd::Zero(s.r0.size());
    for (int c : t.cols) own += CoefOf(f, c) * model.col(c);
    const TermExpr expr = TermExpr::Parse(de.effect.expr);
    const int j = t.joint;
    // The grammar's names of the row's signals at joint j (the other joint's by its own name).
    const std::string names[7] = {"q", "qd", "qdd", "tau_R", j == 0 ? "q_knee" : "q_hip", j == 0 ? "qd_knee" : "qd_hip", "t"};
    std::vector<int> read;
    for (int i = 0; i < 7; ++i)
      if (expr.Reads(names[i]) || (i < 2 && expr.Reads(std::string(kSignal[i]) + (j == 0 ? "_hip" : "_knee"))))
        read.push_back(i);
    for (int i : read) p.signals.push_back({names[i], {}});
    for (size_t k = 0; k < s.m; k += stride) {
      const Eigen::Index row = static_cast<Eigen::Index>(j * s.m + k);
      p.partial.push_back((resid[row] + own[row]) / w[j]);
      p.shape.push_back(de.effect.value != 0 ? own[row] / (w[j] * de.effect.value) : 0.0);
      const TermRow r = RowAt(s, j, s.bank->sample[k]);
      for (size_t q = 0; q < read.size(); ++q) p.signals[q].second.push_back(r.s[static_cast<size_t>(read[q])]);
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

TermSearchResult SearchTerms(const LegParams& params, const std::vector<Rec>& recs, const double w[2],
                             const std::vector<ColumnBank>& banks, const PhysicalScale& scale,
                             const bool at_joint[2], int threads, Diagnosis* D) {
  TermSearchResult out;
  const size_t R = recs.size(), K = D->effects.size();
  std::vector<SearchRec> S;
  for (size_t r = 0; r < R; ++r) S.push_back(Prepare(params, recs[r], banks[r], w, *D));
  std::vector<int> joints;
  for (int j = 0; j < 2; ++j)
    if (at_joint[j] && w[j] > 0 && !(params.one_joint && j == 0)) joints.push_back(j);
  // The model's columns per record: the table's K, then the terms'.
  std::vector<Eigen::MatrixXd> model(R);
  for (size_t r = 0; r < R; ++r) model[r] = S[r].C;
  std::vector<int> cur(K);
  for (size_t k = 0; k < K; ++k) cur[k] = static_cast<int>(k);
  std::vector<Term> terms;
  // The screening rows: every record's train rows, strided to kScreenRows per joint in all.
  size_t train = 0;
  for (const SearchRec& s : S) train += s.mtr;
  const size_t stride = std::max<size_t>(1, (train + kScreenRows - 1) / kScreenRows);
  std::vector<std::pair<size_t, size_t>> at;
  for (size_t r = 0; r < R; ++r)
    for (size_t k = 0; k < S[r].mtr; k += stride) at.push_back({r, k});
  const Eigen::Index N = static_cast<Eigen::Index>(at.size());

  // The measured torque's weighted sum of squares on every fit row, and on the held-out rows.
  double tt_all[2] = {0, 0}, tt_te[2] = {0, 0};
  for (const SearchRec& s : S)
    for (size_t k = 0; k < s.m; ++k)
      for (int j = 0; j < 2; ++j) {
        const double v = std::pow(w[j] * s.rc->meas[j][s.bank->sample[k]], 2);
        tt_all[j] += v;
        if (!s.bank->train[k]) tt_te[j] += v;
      }
  for (int step = 0; step < kMaxTerms; ++step) {
    // Screening against the current model.
    Eigen::MatrixXd Z(2 * N, static_cast<Eigen::Index>(cur.size()));
    Eigen::VectorXd y(2 * N);
    for (Eigen::Index k = 0; k < N; ++k)
      for (Eigen::Index j = 0; j < 2; ++j) {
        const SearchRec& s = S[at[k].first];
        const Eigen::Index row = j * static_cast<Eigen::Index>(s.m) + static_cast<Eigen::Index>(at[k].second);
        y[j * N + k] = s.r0[row];
        for (size_t c = 0; c < cur.size(); ++c) Z(j * N + k, static_cast<Eigen::Index>(c)) = model[at[k].first](row, cur[c]);
      }
    const Screen sc = MakeScreen(S, Z, y, at, w);
    size_t screened = 0;
    std::vector<Scored> top = ScreenAll(S, sc, w, !params.one_joint, joints, threads, &screened);
    if (top.size() > kScreened) top.resize(kScreened);
    if (top.empty()) break;
    // The exact fit of the best: their filtered columns beside the model's.
    std::vector<Eigen::MatrixXd> extra(R);
    std::vector<std::vector<int>> cand_cols(top.size());
    const int base = static_cast<int>(model[0].cols());
    for (size_t r = 0; r < R; ++r) {
      std::vector<Eigen::MatrixXd> parts;
      Eigen::Index width = 0;
      for (const Scored& sd : top) parts.push_back(ExactColumns(S[r], sd.joint, sd.c, w)), width += parts.back().cols();
      extra[r].resize(model[r].rows(), width);
      Eigen::Index c0 = 0;
      for (size_t i = 0; i < parts.size(); ++i) {
        extra[r].middleCols(c0, parts[i].cols()) = parts[i];
        if (r == 0)
          for (Eigen::Index c = 0; c < parts[i].cols(); ++c) cand_cols[i].push_back(base + static_cast<int>(c0 + c));
        c0 += parts[i].cols();
      }
    }
    const Grams g = MakeSearchGrams(S, model, extra, w, D->tau_eff);
    const Fit now = FitCols(g, cur);
    const double margin = kBicMargin + std::log(static_cast<double>(screened));
    int pick = -1;
    std::vector<double> gain(top.size(), -1);
    for (size_t i = 0; i < top.size(); ++i) {
      const int j = top[i].joint;
      std::vector<int> cols = cur;
      cols.insert(cols.end(), cand_cols[i].begin(), cand_cols[i].end());
      const Fit f = FitCols(g, cols);
      if (!f.ok) continue;
      const double drop_te = now.sse_te_j[j] - f.sse_te_j[j];
      // Material over the whole record, not only its held-out end: a term that fades (a drive warming
      // up) is an effect where it acts.
      const bool held = drop_te >= kMinHeldoutGain * now.sse_te_j[j] &&
                        (now.sse_tr - f.sse_tr) + drop_te >= kMinTorqueShare * kMinTorqueShare * tt_all[j];
      const bool loo = R < 2 || now.sse_loo_j[j] - f.sse_loo_j[j] >= kMinHeldoutGain * now.sse_loo_j[j];
      const bool admissible = now.bic - f.bic > margin && held && loo && TermT(f, cand_cols[i]) > kMinT;
      D->term_search.push_back("step " + std::to_string(step + 1) + ": " +
                               CandidateExpr(top[i].c, kJointName[j]) + " (" + kJointName[j] + "): BIC " +
                               Num(f.bic - now.bic) + " (needed < -" + Num(margin) + "), held-out error " +
                               Num(-100 * drop_te / std::max(1e-300, now.sse_te_j[j])) + " %, |t| " +
                               Num(TermT(f, cand_cols[i])) + (admissible ? ": admissible" : ""));
      if (!admissible) continue;
      if (StickPhase(top[i].c) && CoulombNamed(*D, cur, j)) {
        D->term_search.push_back("not a term: " + CandidateExpr(top[i].c, kJointName[j]) + " (" + kJointName[j] +
                                 ") acts only near rest, where the named Coulomb friction's torque is set-valued "
                                 "(sticking: any value within its bound)");
        continue;
      }
      gain[i] = drop_te;
    }
    // The table's own forms at a joint compete first (simplest first): a term that one of them
    // (Coulomb and viscous friction, inertia, stiffness, gain) explains within kParsimony of its
    // held-out gain is that table effect's, which the table's selection judged, not a term. The best
    // form's held-out drop at a joint, once per step.
    double form_drop[2] = {-1, -1};
    std::string form_expr[2];
    for (size_t i = 0; i < top.size(); ++i) {
      if (gain[i] <= 0) continue;
      const int j = top[i].joint;
      if (form_drop[j] < 0) {
        form_drop[j] = 0;
        for (const TableForm& form : TableForms()) {
          std::vector<Eigen::MatrixXd> col(R);
          for (size_t r = 0; r < R; ++r) col[r] = ExactColumns(S[r], j, form.c, w);
          std::vector<int> cols = cur;
          cols.push_back(base);
          const Fit ff = FitCols(MakeSearchGrams(S, model, col, w, D->tau_eff), cols);
          if (ff.ok && (!form.passive || CoefOf(ff, base) > 0) && now.sse_te_j[j] - ff.sse_te_j[j] > form_drop[j])
            form_drop[j] = now.sse_te_j[j] - ff.sse_te_j[j], form_expr[j] = CandidateExpr(form.c, kJointName[j]);
        }
      }
      if (form_drop[j] >= (1 - kParsimony) * gain[i]) {
        D->term_search.push_back("not a term: " + CandidateExpr(top[i].c, kJointName[j]) + " (" + kJointName[j] +
                                 ") is explained as well by the table's form " + form_expr[j]);
        gain[i] = -1;
      }
    }
    double best_gain = 0;
    for (double v : gain) best_gain = std::max(best_gain, v);
    // The simplest admissible within kParsimony of the best's held-out gain.
    for (size_t i = 0; i < top.size(); ++i)
      if (gain[i] >= (1 - kParsimony) * best_gain && gain[i] > 0 &&
          (pick < 0 || top[i].c.Complexity() < top[static_cast<size_t>(pick)].c.Complexity()))
        pick = static_cast<int>(i);
    if (pick < 0) break;
    // The term joins the model.
    Term t{top[static_cast<size_t>(pick)].joint, top[static_cast<size_t>(pick)].c, {}};
    for (size_t r = 0; r < R; ++r) {
      const std::vector<int>& cc = cand_cols[static_cast<size_t>(pick)];
      Eigen::MatrixXd grown(model[r].rows(), model[r].cols() + static_cast<Eigen::Index>(cc.size()));
      grown << model[r], extra[r].middleCols(cc[0] - base, static_cast<Eigen::Index>(cc.size()));
      model[r] = std::move(grown);
    }
    for (size_t c = 0; c < cand_cols[static_cast<size_t>(pick)].size(); ++c) t.cols.push_back(base + static_cast<int>(c));
    cur.insert(cur.end(), t.cols.begin(), t.cols.end());
    D->term_search.push_back("named " + CandidateExpr(t.c, kJointName[t.joint]) + " at the " + kJointName[t.joint]);
    terms.push_back(t);
    out.changed = true;
    // Backward elimination of the table's effects the term makes redundant.
    DropRedundant(S, model, w, scale, K, tt_te, D, &cur);
  }
  if (!out.changed) return out;

  // The final model: the kept table effects refitted, the terms; each one's held-out share.
  const std::vector<Eigen::MatrixXd> none(R, Eigen::MatrixXd(model[0].rows(), 0));
  const Grams g = MakeSearchGrams(S, model, none, w, D->tau_eff);
  const Fit f = FitCols(g, cur), f0 = FitCols(g, {});
  auto share = [&](const std::vector<int>& cols) {
    return f0.sse_te > 0 ? 100 * (FitCols(g, Without(cur, cols)).sse_te - f.sse_te) / f0.sse_te : 0.0;
  };
  // The effects at coefficients `coef` of the columns `sorted` (in that order).
  auto effects_at = [&](const Eigen::VectorXd& coef, const std::vector<int>& sorted, const Fit* fit) {
    std::vector<DiagnosedEffect> e;
    for (int c : cur) {
      if (c >= static_cast<int>(K)) continue;
      DiagnosedEffect de = D->effects[static_cast<size_t>(c)];
      const double x = coef[static_cast<Eigen::Index>(std::find(sorted.begin(), sorted.end(), c) - sorted.begin())];
      if (fit) de.ci_lo = x - 1.96 * SeOf(*fit, c), de.ci_hi = x + 1.96 * SeOf(*fit, c), de.explained_pct = share({c});
      de.effect.value = x;
      e.push_back(de);
    }
    for (const Term& t : terms) {
      DiagnosedEffect de = TermEffect(t, coef, sorted, fit);
      if (fit) de.explained_pct = share(t.cols);
      e.push_back(de);
    }
    return e;
  };
  D->effects = effects_at(f.coef, f.cols, &f);
  D->term_plots = TermPlots(S[0], model[0], f, terms, D->effects, w);
  D->extended = params;
  for (const DiagnosedEffect& de : D->effects) D->extended.effects.push_back(de.effect);
  if (R >= 2)
    for (size_t r = 0; r < R; ++r) {
      std::vector<Effect> e;
      const Eigen::VectorXd x = FitLeavingOut(g, cur, r);
      if (x.size() > 0)
        for (const DiagnosedEffect& de : effects_at(x, cur, nullptr)) e.push_back(de.effect);
      out.left_out.push_back(e);
    }
  return out;
}

}  // namespace torque_fit
}  // namespace exotwin
