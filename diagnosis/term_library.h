// The candidate terms of the search for terms beyond the table (DESIGN.md "Terms beyond the
// table"): a coefficient times a product of at most two factors, each one function of one of the
// record's signals, written in model/term_expr.h's grammar. The library is generated from the
// grammar (every function of every signal, their products), not from a list of known forms.
//
// Factors (x one of the term joint's q, qd, qdd, tau_R, the other joint's q and qd, or t):
//   x, abs(x), sgn(x), pos(x), x^2                      (no inner parameter)
//   exp(-t / T)                                         (T, s: a drift or warm-up)
//   exp(-(qd / v)^2), tanh(qd / v)                      (v, rad/s: a velocity scale)
//   sin(k * x + phi) for x an angle                     (k, rad^-1; phi fitted linearly with cos)
// Terms: every factor alone, every factor times sgn(qd) or qd (a friction's or a damping's carrier),
// and every product of two factors without inner parameter (of two signals, or x^2 sgn(x) and x pos(x)).
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// The signals of a term at its joint j (o: the other joint).
enum class TermSignal { kQ, kQd, kQdd, kTauR, kQOther, kQdOther, kT };
enum class TermFn { kId, kAbs, kSgn, kPos, kSquare, kExpDecay, kGauss, kTanh, kSin };

struct TermFactor {
  TermFn fn = TermFn::kId;
  TermSignal sig = TermSignal::kQ;
  double p = 0;  // the inner parameter (T, v or k); 0 for factors without one
  bool operator==(const TermFactor& o) const { return fn == o.fn && sig == o.sig && p == o.p; }
};

// A candidate: one or two factors. A factor kSin makes two columns (its sin and cos, phi fitted).
struct TermCandidate {
  std::vector<TermFactor> factors;
  bool Paired() const;      // holds a kSin factor (two columns)
  int Complexity() const;   // factors + inner parameters (simplest first)
};

// One sample's signals at the term's joint.
struct TermRow {
  double s[7];  // by TermSignal
};

// The factor's value; for kSin, `cosine` selects cos(k x) instead of sin(k x) (phi = 0).
double FactorValue(const TermFactor& f, const TermRow& r, bool cosine = false);

// The candidate's value (its first column; `cosine`: the kSin factor's cos column).
double CandidateValue(const TermCandidate& c, const TermRow& r, bool cosine = false);

// Scales of the records that place the inner parameters' grids: the longest record's duration (s),
// the term joint's RMS velocity (rad/s) and the angle range of each joint (rad).
struct TermScales {
  double duration = 1, qd_rms = 1, q_range = 1, q_other_range = 1;
};

// The library at one joint: every candidate of the header's grammar with the inner parameters on
// log-spaced grids from `s`. A one-joint device (other_joint false) has no other joint's signals.
std::vector<TermCandidate> TermLibrary(const TermScales& s, bool other_joint);

// The grid of the inner parameter of `fn` (the library's), ascending.
std::vector<double> InnerGrid(TermFn fn, const TermScales& s);

// The expression text of a candidate at joint `joint` ("hip" or "knee") in model/term_expr.h's
// grammar, its kSin factor at phase `phi` (rad). Inner parameters are printed to 4 significant
// digits; RoundedInner gives the value printed, so a column is evaluated from what is written.
std::string CandidateExpr(const TermCandidate& c, const std::string& joint, double phi = 0);
double RoundedInner(double p);

}  // namespace exotwin
