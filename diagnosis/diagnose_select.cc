#include "diagnosis/diagnose_select.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <Eigen/Eigenvalues>

#include "formats/number_text.h"
#include "diagnosis/fit_families.h"
#include "model/effect_families.h"
#include "model/leg_dynamics.h"
#include "model/passive_torque.h"
#include "sim/plant_effects.h"

namespace exotwin {
namespace {

const char* kJoint[2] = {"hip", "knee"};

std::string Num(double v) { return NumberText(v, 4); }

// Solves the normalized normal equations of `cols`; false when nearly singular.
bool Solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd* x, Eigen::MatrixXd* Ainv) {
  const Eigen::Index p = A.rows();
  Eigen::VectorXd d = A.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd An = d.asDiagonal() * A * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(An);
  if (!(es.eigenvalues()[0] > 1e-8 * es.eigenvalues()[p - 1])) return false;
  const Eigen::MatrixXd inv = d.asDiagonal() *
                              (es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
                               es.eigenvectors().transpose()) *
                              d.asDiagonal();
  *x = inv * b;
  if (Ainv) *Ainv = inv;
  return true;
}

Eigen::MatrixXd Sub(const Eigen::MatrixXd& G, const std::vector<int>& c) {
  Eigen::MatrixXd A(c.size(), c.size());
  for (size_t a = 0; a < c.size(); ++a)
    for (size_t b = 0; b < c.size(); ++b) A(a, b) = G(c[a], c[b]);
  return A;
}
Eigen::VectorXd Sub(const Eigen::VectorXd& v, const std::vector<int>& c) {
  Eigen::VectorXd o(c.size());
  for (size_t a = 0; a < c.size(); ++a) o[a] = v[c[a]];
  return o;
}

double Sse(const Eigen::MatrixXd& G, const Eigen::VectorXd& b, double rr, const Eigen::VectorXd& x) {
  return std::max(0.0, rr - 2 * x.dot(b) + x.dot(G * x));
}

// The normal equations of `cols` over every record's rows but `left_out`'s.
void SumLeavingOut(const Grams& g, const std::vector<int>& cols, size_t left_out, Eigen::MatrixXd* A, Eigen::VectorXd* b) {
  *A = Eigen::MatrixXd::Zero(cols.size(), cols.size());
  *b = Eigen::VectorXd::Zero(cols.size());
  for (size_t k = 0; k < g.records(); ++k)
    for (int j = 0; j < 2; ++j)
      if (k != left_out) *A += Sub(g.Grec[j][k], cols), *b += Sub(g.brec[j][k], cols);
}

}  // namespace

Grams MakeGrams(const std::vector<ColumnBank>& banks) {
  const Eigen::Index C = banks.at(0).X.cols();
  Grams g;
  g.Gtr = Eigen::MatrixXd::Zero(C, C);
  g.btr = Eigen::VectorXd::Zero(C);
  for (int j = 0; j < 2; ++j) g.Gte[j] = Eigen::MatrixXd::Zero(C, C), g.bte[j] = Eigen::VectorXd::Zero(C);
  for (const ColumnBank& b : banks) {
    const Eigen::Index m = static_cast<Eigen::Index>(b.sample.size());
    const Eigen::Index mtr = static_cast<Eigen::Index>(std::count(b.train.begin(), b.train.end(), true));
    for (Eigen::Index j = 0; j < 2; ++j) {  // train rows come first in each joint block
      const auto tr = b.X.middleRows(j * m, mtr);
      const auto te = b.X.middleRows(j * m + mtr, m - mtr);
      Eigen::MatrixXd Gt = Eigen::MatrixXd::Zero(C, C), Ge = Eigen::MatrixXd::Zero(C, C);
      Gt.selfadjointView<Eigen::Lower>().rankUpdate(tr.transpose());
      Ge.selfadjointView<Eigen::Lower>().rankUpdate(te.transpose());
      Gt = Gt.selfadjointView<Eigen::Lower>();
      Ge = Ge.selfadjointView<Eigen::Lower>();
      const Eigen::VectorXd bt = tr.transpose() * b.r.segment(j * m, mtr);
      const Eigen::VectorXd be = te.transpose() * b.r.segment(j * m + mtr, m - mtr);
      const double rt = b.r.segment(j * m, mtr).squaredNorm(), re = b.r.segment(j * m + mtr, m - mtr).squaredNorm();
      g.Gtr += Gt, g.btr += bt, g.rrtr += rt;
      g.Gte[j] += Ge, g.bte[j] += be, g.rrte[j] += re;
      g.Grec[j].push_back(Gt + Ge);
      g.brec[j].push_back(bt + be);
      g.rrrec[j].push_back(rt + re);
    }
    g.n_tr += static_cast<double>(2 * mtr);
  }
  g.n_eff = g.n_tr;
  return g;
}

Fit FitCols(const Grams& g, std::vector<int> cols, bool leave_one_out) {
  std::sort(cols.begin(), cols.end());
  cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
  Fit f;
  f.cols = cols;
  const size_t R = g.records();
  const int p = static_cast<int>(cols.size());
  auto totals = [&] {
    f.sse_te = f.sse_te_j[0] + f.sse_te_j[1];
    f.sse_loo = f.sse_loo_j[0] + f.sse_loo_j[1];
  };
  if (p == 0) {
    f.ok = true;
    f.sse_tr = g.rrtr;
    f.bic = g.n_eff * std::log(g.rrtr / g.n_tr);
    for (int j = 0; j < 2; ++j) {
      f.sse_te_j[j] = g.rrte[j];
      if (R >= 2)
        for (double rr : g.rrrec[j]) f.sse_loo_j[j] += rr;
    }
    totals();
    return f;
  }
  const Eigen::MatrixXd A = Sub(g.Gtr, cols);
  const Eigen::VectorXd bb = Sub(g.btr, cols);
  Eigen::MatrixXd Ainv;
  if (!Solve(A, bb, &f.coef, &Ainv)) return f;
  f.sse_tr = std::max(1e-300, Sse(A, bb, g.rrtr, f.coef));
  for (int j = 0; j < 2; ++j) f.sse_te_j[j] = Sse(Sub(g.Gte[j], cols), Sub(g.bte[j], cols), g.rrte[j], f.coef);
  // Covariance with the residual variance and the autocorrelation length n_tr / n_eff.
  const double s2 = f.sse_tr / (g.n_tr - p) * (g.n_tr / g.n_eff);
  f.se = (Ainv.diagonal() * s2).cwiseMax(0).cwiseSqrt();
  f.bic = g.n_eff * std::log(f.sse_tr / g.n_tr) + p * std::log(g.n_eff);
  if (R >= 2 && leave_one_out) {
    for (size_t k = 0; k < R; ++k) {
      const Eigen::VectorXd x = FitLeavingOut(g, cols, k);
      if (x.size() == 0) return f;  // not ok: a record's absence makes the set unidentifiable
      for (int j = 0; j < 2; ++j)
        f.sse_loo_j[j] += Sse(Sub(g.Grec[j][k], cols), Sub(g.brec[j][k], cols), g.rrrec[j][k], x);
    }
  }
  totals();
  f.ok = true;
  return f;
}

Eigen::VectorXd FitLeavingOut(const Grams& g, const std::vector<int>& cols, size_t left_out) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  SumLeavingOut(g, cols, left_out, &A, &b);
  Eigen::VectorXd x;
  if (!Solve(A, b, &x, nullptr)) return {};
  return x;
}

bool SolveSigned(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<int>& sign, Eigen::VectorXd* x) {
  const int n = static_cast<int>(b.size());
  std::vector<char> passive(n);  // fitted (free or off its bound); else held at zero
  for (int i = 0; i < n; ++i) passive[i] = sign[i] == 0;
  // The unconstrained least squares of the passive set, zero elsewhere.
  auto solve = [&](Eigen::VectorXd* z) {
    std::vector<int> p;
    for (int i = 0; i < n; ++i)
      if (passive[i]) p.push_back(i);
    *z = Eigen::VectorXd::Zero(n);
    if (p.empty()) return true;
    Eigen::VectorXd zp;
    if (!Solve(Sub(A, p), Sub(b, p), &zp, nullptr)) return false;
    for (size_t k = 0; k < p.size(); ++k) (*z)[p[k]] = zp[static_cast<Eigen::Index>(k)];
    return true;
  };
  if (!solve(x)) return false;  // feasible: only free variables are off zero
  // Each outer step frees the held variable whose bound costs most (the largest w_i = sign_i times
  // the descent direction b - A x); the inner loop steps back along the segment to the new solution
  // until every constrained variable keeps its sign. Finite: the cost drops at each outer step.
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    const Eigen::VectorXd grad = b - A * *x;
    int best = -1;
    double wbest = 0;
    for (int i = 0; i < n; ++i) {
      if (passive[i]) continue;
      const double scale = std::abs(b[i]) + (A.row(i).cwiseAbs() * x->cwiseAbs()).sum();
      const double wi = sign[i] * grad[i];
      if (wi > 1e-12 * scale && wi > wbest) wbest = wi, best = i;
    }
    if (best < 0) return true;  // Kuhn-Tucker conditions hold
    passive[best] = 1;
    for (int inner = 0; inner < n + 1; ++inner) {
      Eigen::VectorXd z;
      if (!solve(&z)) return false;
      double step = 1;
      int blocking = -1;
      for (int i = 0; i < n; ++i)
        if (passive[i] && sign[i] != 0 && sign[i] * z[i] <= 0) {
          const double d = (*x)[i] - z[i];
          const double s = d != 0 ? (*x)[i] / d : 0.0;
          if (s < step) step = s, blocking = i;
        }
      if (blocking < 0) {
        *x = z;
        break;
      }
      if (blocking == best && step <= 0) {  // rounding: the freed variable cannot move off its bound
        passive[best] = 0;
        return true;
      }
      *x += step * (z - *x);
      for (int i = 0; i < n; ++i)
        if (passive[i] && sign[i] != 0 && (i == blocking || sign[i] * (*x)[i] <= 0)) passive[i] = 0, (*x)[i] = 0;
    }
  }
  return true;
}

Fit FitColsSigned(const Grams& g, const std::vector<int>& cols, const std::vector<int>& sign) {
  std::vector<int> local(cols.size());
  for (size_t k = 0; k < cols.size(); ++k) local[k] = sign[static_cast<size_t>(cols[k])];
  Eigen::VectorXd x;
  if (!SolveSigned(Sub(g.Gtr, cols), Sub(g.btr, cols), local, &x)) return Fit{};
  std::vector<int> passive;
  for (size_t k = 0; k < cols.size(); ++k)
    if (local[k] == 0 || x[static_cast<Eigen::Index>(k)] != 0) passive.push_back(cols[k]);
  return FitCols(g, passive);
}

Eigen::VectorXd FitLeavingOutSigned(const Grams& g, const std::vector<int>& cols, const std::vector<int>& sign,
                                    size_t left_out) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  SumLeavingOut(g, cols, left_out, &A, &b);
  std::vector<int> local(cols.size());
  for (size_t k = 0; k < cols.size(); ++k) local[k] = sign[static_cast<size_t>(cols[k])];
  Eigen::VectorXd x;
  if (!SolveSigned(A, b, local, &x)) return {};
  return x;
}

std::vector<int> ColumnsOf(const ColumnBank& bank, const std::vector<int>& set) {
  std::vector<int> cols;
  for (int c : set) cols.insert(cols.end(), bank.candidates[c].cols.begin(), bank.candidates[c].cols.end());
  std::sort(cols.begin(), cols.end());
  cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
  return cols;
}

double CoefOf(const Fit& f, int col) {
  for (size_t i = 0; i < f.cols.size(); ++i)
    if (f.cols[i] == col) return f.coef[i];
  return 0;
}
double SeOf(const Fit& f, int col) {
  for (size_t i = 0; i < f.cols.size(); ++i)
    if (f.cols[i] == col) return f.se[i];
  return 0;
}

DiagnosedEffect ToEffect(const Candidate& c, const Eigen::VectorXd& coef, const std::vector<int>& cols) {
  Fit f;
  f.cols = cols, f.coef = coef, f.se = Eigen::VectorXd::Zero(coef.size());
  return ToEffect(c, f);
}

DiagnosedEffect ToEffect(const Candidate& c, const Fit& f) {
  DiagnosedEffect d;
  Effect& e = d.effect;
  e.name = c.name, e.joint = kJoint[c.joint], e.axis = c.axis;
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  d.ci_lo = v - 1.96 * se, d.ci_hi = v + 1.96 * se;
  e.value = v;
  const FitFamily& family = FitFamilyOf(c.name);
  e.unit = family.family->unit;
  if (family.to_effect) family.to_effect(c, f, &d);
  return d;
}

bool Plausible(const DiagnosedEffect& d, const PhysicalScale& s, std::string* why) {
  const std::string no = FitFamilyOf(d.effect.name).implausible(d.effect, s);
  if (why) *why = no;
  return no.empty();
}

PhysicalScale ScaleOf(const LegParams& params, const std::vector<ScaleRecord>& recs) {
  PhysicalScale scale;
  const LumpedParams tot = params.Total();
  const double Xd[2] = {tot.X1, tot.X2}, Yd[2] = {tot.Y1, tot.Y2};
  LegParams rigid = params;
  rigid.effects.clear();
  for (int j = 0; j < 2; ++j) {
    scale.q_min[j] = 1e300, scale.q_max[j] = -1e300;
    scale.distal_moment[j] = std::hypot(Xd[j], Yd[j]);
    // Means over every record (strided): the twin's M_jj, the compliant part's J_c (the human when
    // there is one, else the whole chain), and the motion's effective angular frequency
    // w = RMS(qdd) / RMS(qd) (of the velocity: a link that spins through many turns has a slow
    // angle but a fast velocity). The strap's neglected dynamics are J_c w^2.
    const LumpedParams& compliant = params.human ? *params.human : tot;
    double msum = 0, jc = 0, v2 = 0, a2 = 0, tc2 = 0, cnt = 0, qsum = 0, qsq = 0, qn = 0;
    for (const ScaleRecord& rc : recs) {
      const Kinematics& kin = *rc.kin;
      const size_t n = kin.t.size();
      for (size_t i = 0; i < n; ++i) {
        qsum += kin.q[j][i], qsq += kin.q[j][i] * kin.q[j][i], qn += 1;
        scale.q_min[j] = std::min(scale.q_min[j], kin.q[j][i]);
        scale.q_max[j] = std::max(scale.q_max[j], kin.q[j][i]);
        scale.tau_max[j] = std::max(scale.tau_max[j], std::abs((*rc.tau[j])[i]));
      }
      const size_t stride = std::max<size_t>(1, n / 4000);
      for (size_t i = 0; i < n; i += stride) {
        const Eigen::Vector2d q(kin.q[0][i], kin.q[1][i]), qd(kin.qd[0][i], kin.qd[1][i]),
            qdd(kin.qdd[0][i], kin.qdd[1][i]);
        msum += MassMatrix(tot, params.L1, q[1])(j, j);
        jc += MassMatrix(compliant, params.L1, q[1])(j, j);
        v2 += qd[j] * qd[j], a2 += qdd[j] * qdd[j], cnt += 1;
        const double tc = CompliantPartTorque(rigid, q, qd, qdd)[j];
        scale.tau_C_max[j] = std::max(scale.tau_C_max[j], std::abs(tc));
        tc2 += tc * tc;
      }
    }
    if (qn > 0) scale.q_rms[j] = std::sqrt(std::max(0.0, qsq / qn - (qsum / qn) * (qsum / qn)));
    scale.M_jj[j] = msum / cnt;
    scale.tau_C_rms[j] = std::sqrt(tc2 / cnt);
    scale.strap_dynamics[j] = v2 > 0 ? jc / cnt * a2 / v2 : 0.0;
  }
  return scale;
}

namespace {

// Significant and plausible inside fit `f`?
bool Admissible(const Candidate& c, const Fit& f, const PhysicalScale& s) {
  if (!f.ok) return false;
  const FitFamily& family = FitFamilyOf(c.name);
  const bool significant = family.significant ? family.significant(c, f)
                                              : std::abs(CoefOf(f, c.cols[0])) > kMinT * SeOf(f, c.cols[0]);
  return significant && Plausible(ToEffect(c, f), s);
}

bool AllAdmissible(const ColumnBank& bank, const std::vector<int>& set, const Fit& f, const PhysicalScale& s) {
  if (!f.ok) return false;
  for (int c : set)
    if (!Admissible(bank.candidates[c], f, s)) return false;
  return true;
}

std::string Label(const ColumnBank& bank, const std::vector<int>& set) {
  std::string o;
  for (int c : set) o += (o.empty() ? "" : " + ") + bank.candidates[c].Label();
  return o.empty() ? "rigid twin" : o;
}

}  // namespace

bool Conflicts(const Candidate& a, const Candidate& b) {
  if (a.joint == b.joint) {
    if (a.name == b.name) return true;  // gravity X and Y: one at a time
    // One of an exclusive group per joint (EffectFamily::exclusive: the plant's one internal hinge).
    const EffectFamily *fa = FindFamily(a.name), *fb = FindFamily(b.name);
    if (fa && fb && *fa->exclusive && std::string(fa->exclusive) == fb->exclusive) return true;
  }
  for (int x : a.cols)
    if (std::find(b.cols.begin(), b.cols.end(), x) != b.cols.end()) return true;  // nested (offset)
  return false;
}

std::vector<int> SelectEffects(const ColumnBank& bank, const Grams& g, const PhysicalScale& scale,
                               int max_effects, bool loo, Fit* fit, SelectionTrace* trace) {
  std::vector<int> set;
  const Fit rigid = FitCols(g, {});
  Fit cur = rigid;
  std::set<std::vector<int>> seen{{}};
  // The held-out error at joint j drops by at least `frac` of its value under `ref`.
  auto held_ok = [&](const Fit& f, const Fit& ref, int j, double frac) {
    return f.sse_te_j[j] <= (1 - frac) * ref.sse_te_j[j] &&
           (!loo || f.sse_loo_j[j] <= (1 - frac) * ref.sse_loo_j[j]);
  };
  // Material: the drop is at least (kMinTorqueShare of the measured torque's RMS)^2 there.
  auto material = [&](const Fit& f, const Fit& ref, int j) {
    return ref.sse_te_j[j] - f.sse_te_j[j] >= kMinTorqueShare * kMinTorqueShare * g.tt_te[j];
  };
  std::string last_rejected;
  auto score = [&](const Fit& f) {
    std::string s = "BIC " + Num(f.bic - rigid.bic) + ", held-out SSE " + Num(f.sse_te);
    if (loo) s += ", left-out records SSE " + Num(f.sse_loo);
    return s;
  };
  while (static_cast<int>(set.size()) < max_effects) {
    struct Option {
      int c;
      Fit f;
    };
    std::vector<Option> ok;
    double best_rejected_bic = 1e300;
    last_rejected.clear();
    for (int c = 0; c < static_cast<int>(bank.candidates.size()); ++c) {
      if (std::find(set.begin(), set.end(), c) != set.end()) continue;
      if (std::any_of(set.begin(), set.end(),
                      [&](int s) { return Conflicts(bank.candidates[s], bank.candidates[c]); }))
        continue;
      std::vector<int> next = set;
      next.push_back(c);
      Fit f = FitCols(g, ColumnsOf(bank, next));
      if (!f.ok || !(f.bic < cur.bic - kBicMargin)) continue;
      const int j = bank.candidates[c].joint;
      if (!held_ok(f, cur, j, kMinHeldoutGain) || !material(f, cur, j)) {
        if (f.bic < best_rejected_bic)
          best_rejected_bic = f.bic,
          last_rejected = bank.candidates[c].Label() + " (BIC " + Num(f.bic - cur.bic) + ") lowers the held-out " +
                          "error at the " + kJoint[j] + " by " + Num(100 * (1 - f.sse_te_j[j] / cur.sse_te_j[j])) +
                          " %" + (loo ? " and on left-out records by " + Num(100 * (1 - f.sse_loo_j[j] / cur.sse_loo_j[j])) + " %" : "") +
                          " (needed: " + Num(100 * kMinHeldoutGain) + " % and (" + Num(100 * kMinTorqueShare) +
                          " % of the " + g.scale_name + " RMS)^2)";
        continue;
      }
      if (!AllAdmissible(bank, next, f, scale)) continue;
      ok.push_back({c, std::move(f)});
    }
    if (ok.empty()) {
      if (trace && !last_rejected.empty()) trace->steps.push_back("stop: the best remaining, " + last_rejected);
      break;
    }
    std::sort(ok.begin(), ok.end(), [](const Option& a, const Option& b) { return a.f.bic < b.f.bic; });
    const Option* best = &ok[0];
    // The simplest explanation: fewer parameters win unless the richer one lowers the held-out
    // error by more than kParsimony of it.
    const int bj = bank.candidates[best->c].joint;
    for (const Option& o : ok)
      if (bank.candidates[o.c].joint == bj &&
          bank.candidates[o.c].cols.size() < bank.candidates[best->c].cols.size() &&
          !held_ok(best->f, o.f, bj, kParsimony)) {
        if (trace)
          trace->steps.push_back(bank.candidates[o.c].Label() + " preferred to " +
                                 bank.candidates[best->c].Label() + " (fewer parameters, held-out within " +
                                 Num(100 * kParsimony) + " %)");
        best = &o;
        break;
      }
    set.push_back(best->c);
    cur = best->f;
    if (trace) trace->steps.push_back("add " + bank.candidates[best->c].Label() + ": " + score(cur));
    // Backward elimination: drop an effect that no longer earns its margin in the joint fit.
    for (bool removed = true; removed && set.size() > 1;) {
      removed = false;
      int worst = -1;
      Fit worst_fit;
      for (size_t k = 0; k < set.size(); ++k) {
        std::vector<int> less = set;
        less.erase(less.begin() + static_cast<long>(k));
        Fit f = FitCols(g, ColumnsOf(bank, less));
        if (!AllAdmissible(bank, less, f, scale)) continue;
        if (f.bic < cur.bic + kBicMargin && (worst < 0 || f.bic < worst_fit.bic)) worst = static_cast<int>(k), worst_fit = f;
      }
      if (worst >= 0) {
        if (trace) trace->steps.push_back("remove " + bank.candidates[set[worst]].Label() + ": " + score(worst_fit));
        set.erase(set.begin() + worst);
        cur = worst_fit;
        removed = true;
      }
    }
    std::vector<int> key = set;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) break;
  }
  if (trace) trace->steps.push_back("chosen: " + Label(bank, set));
  *fit = cur;
  return set;
}

}  // namespace exotwin
