#include "diagnosis/term_library.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace exotwin {
namespace {

constexpr TermFn kBasicFns[] = {TermFn::kId, TermFn::kAbs, TermFn::kSgn, TermFn::kPos, TermFn::kSquare};

// sgn as coulomb_friction's closed form (model/effect_families.cc) and model/term_expr.h: 0 at 0.
double Sgn(double x) { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }

bool HasInner(TermFn fn) { return fn == TermFn::kExpDecay || fn == TermFn::kGauss || fn == TermFn::kTanh || fn == TermFn::kSin; }

std::string SignalName(TermSignal s, const std::string& joint) {
  const std::string other = joint == "hip" ? "knee" : "hip";
  switch (s) {
    case TermSignal::kQ: return "q";
    case TermSignal::kQd: return "qd";
    case TermSignal::kQdd: return "qdd";
    case TermSignal::kTauR: return "tau_R";
    case TermSignal::kQOther: return "q_" + other;
    case TermSignal::kQdOther: return "qd_" + other;
    case TermSignal::kT: return "t";
  }
  return "";
}

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

std::string FactorExpr(const TermFactor& f, const std::string& joint, double phi) {
  const std::string x = SignalName(f.sig, joint);
  switch (f.fn) {
    case TermFn::kId: return x;
    case TermFn::kAbs: return "abs(" + x + ")";
    case TermFn::kSgn: return "sgn(" + x + ")";
    case TermFn::kPos: return "pos(" + x + ")";
    case TermFn::kSquare: return x + "^2";
    case TermFn::kExpDecay: return "exp(-" + x + " / " + Num(f.p) + ")";
    case TermFn::kGauss: return "exp(-(" + x + " / " + Num(f.p) + ")^2)";
    case TermFn::kTanh: return "tanh(" + x + " / " + Num(f.p) + ")";
    case TermFn::kSin: {
      const double ph = RoundedInner(phi);
      std::string s = "sin(" + Num(f.p) + " * " + x;
      if (ph > 0) s += " + " + Num(ph);
      if (ph < 0) s += " - " + Num(-ph);
      return s + ")";
    }
  }
  return "";
}

std::vector<double> LogGrid(double lo, double hi, int n) {
  std::vector<double> g(n);
  for (int i = 0; i < n; ++i) g[i] = RoundedInner(lo * std::pow(hi / lo, i / double(n - 1)));
  return g;
}

}  // namespace

bool TermCandidate::Paired() const {
  for (const TermFactor& f : factors)
    if (f.fn == TermFn::kSin) return true;
  return false;
}

int TermCandidate::Complexity() const {
  int c = 0;
  for (const TermFactor& f : factors) c += 1 + (HasInner(f.fn) ? 1 : 0) + (f.fn == TermFn::kSin ? 1 : 0);
  return c;
}

double FactorValue(const TermFactor& f, const TermRow& r, bool cosine) {
  const double x = r.s[static_cast<int>(f.sig)];
  switch (f.fn) {
    case TermFn::kId: return x;
    case TermFn::kAbs: return std::abs(x);
    case TermFn::kSgn: return Sgn(x);
    case TermFn::kPos: return x > 0 ? 1.0 : 0.0;
    case TermFn::kSquare: return x * x;
    case TermFn::kExpDecay: return std::exp(-x / f.p);
    case TermFn::kGauss: return std::exp(-(x / f.p) * (x / f.p));
    case TermFn::kTanh: return std::tanh(x / f.p);
    case TermFn::kSin: return cosine ? std::cos(f.p * x) : std::sin(f.p * x);
  }
  return 0;
}

double CandidateValue(const TermCandidate& c, const TermRow& r, bool cosine) {
  double v = 1;
  for (const TermFactor& f : c.factors) v *= FactorValue(f, r, cosine);
  return v;
}

double RoundedInner(double p) { return std::strtod(Num(p).c_str(), nullptr); }

std::vector<double> InnerGrid(TermFn fn, const TermScales& s) {
  switch (fn) {
    case TermFn::kExpDecay: return LogGrid(s.duration / 30, 3 * s.duration, 10);
    case TermFn::kGauss:
    case TermFn::kTanh: return LogGrid(0.03 * s.qd_rms, 3 * s.qd_rms, 10);
    case TermFn::kSin: return LogGrid(M_PI / s.q_range, 60 / s.q_range, 14);
    default: return {};
  }
}

std::vector<TermCandidate> TermLibrary(const TermScales& s, bool other_joint) {
  using S = TermSignal;
  std::vector<S> sigs = {S::kQ, S::kQd, S::kQdd, S::kTauR};
  if (other_joint) sigs.insert(sigs.end(), {S::kQOther, S::kQdOther});
  std::vector<TermFactor> basic, all;
  for (S sig : sigs)
    for (TermFn fn : kBasicFns) basic.push_back({fn, sig, 0});
  basic.push_back({TermFn::kId, S::kT, 0});
  all = basic;
  for (double T : InnerGrid(TermFn::kExpDecay, s)) all.push_back({TermFn::kExpDecay, S::kT, T});
  for (TermFn fn : {TermFn::kGauss, TermFn::kTanh})
    for (double v : InnerGrid(fn, s)) all.push_back({fn, S::kQd, v});
  for (double k : InnerGrid(TermFn::kSin, s)) all.push_back({TermFn::kSin, S::kQ, k});
  if (other_joint) {
    TermScales o = s;
    o.q_range = s.q_other_range;
    for (double k : InnerGrid(TermFn::kSin, o)) all.push_back({TermFn::kSin, S::kQOther, k});
  }
  std::vector<TermCandidate> lib;
  for (const TermFactor& f : all)  // sin(k q + phi) alone at the term's joint is torque_ripple's form
    if (!(f.fn == TermFn::kSin && f.sig == S::kQ)) lib.push_back({{f}});
  for (const TermFactor& carrier : {TermFactor{TermFn::kSgn, S::kQd, 0}, TermFactor{TermFn::kId, S::kQd, 0}})
    for (const TermFactor& f : all)
      if (HasInner(f.fn) || f.sig != S::kQd || f.fn == TermFn::kSquare) lib.push_back({{f, carrier}});
  for (size_t a = 0; a < basic.size(); ++a)
    for (size_t b = a + 1; b < basic.size(); ++b) {
      // One signal's functions multiply into one of them, but for x^2 sgn(x) (= x abs(x), odd) and
      // x pos(x) (one-sided, a ramp).
      if (basic[a].sig == basic[b].sig &&
          !(basic[a].fn == TermFn::kSgn && basic[b].fn == TermFn::kSquare) &&
          !(basic[a].fn == TermFn::kId && basic[b].fn == TermFn::kPos))
        continue;
      const bool carrier = [&] {
        for (const TermFactor& f : {basic[a], basic[b]})
          if (f.sig == S::kQd && (f.fn == TermFn::kSgn || f.fn == TermFn::kId)) return true;
        return false;
      }();
      if (!carrier) lib.push_back({{basic[a], basic[b]}});  // the carrier products are above
    }
  return lib;
}

std::string CandidateExpr(const TermCandidate& c, const std::string& joint, double phi) {
  std::string s;
  for (const TermFactor& f : c.factors) s += (s.empty() ? "" : " * ") + FactorExpr(f, joint, phi);
  return s;
}

}  // namespace exotwin
