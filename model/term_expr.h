// A term beyond DESIGN.md's effect table (DESIGN.md "Terms beyond the table"): `value * expr` added
// to tau_R at its joint (stage link) or to the reading tau_S (stage sensor). This file is the grammar
// and its evaluator; every command that reads a model file evaluates terms through it.
//
// Grammar (whitespace between tokens is free):
//   expr    := sum
//   sum     := product (('+' | '-') product)*
//   product := unary (('*' | '/') unary)*
//   unary   := '-' unary | power
//   power   := atom ('^' number)?          -- the exponent is a number literal (e.g. 2, 0.5, -1)
//   atom    := number | signal | func '(' expr ')' | '(' expr ')'
//   signal  := q | qd | qdd | tau_R | q_hip | q_knee | qd_hip | qd_knee | t
//   func    := sgn | abs | exp | sin | cos | tanh | pos
// q, qd, qdd, tau_R are the term's own joint's; t is s from the record's or run's start. sgn is the
// sign coulomb_friction's closed form uses (CoulombSign, model/effect_families.h: 0 at 0); pos(x) is
// 1 where x > 0, else 0. A default-constructed TermExpr is the empty expression, which evaluates to 0.
#pragma once
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace exotwin {

// The signals a term reads at one sample. tau_R: the rigid twin's actuator torque at the term's
// joint where the motion is given (predict, diagnose), the actuator torque applied at that step in
// the forward plant (replay, runs).
struct TermSignals {
  double q = 0, qd = 0, qdd = 0, tau_R = 0;  // the term's joint
  double q_hip = 0, q_knee = 0, qd_hip = 0, qd_knee = 0;
  double t = 0;
};

// A parse error: what was expected and the 0-based character position in the text.
class TermExprError : public std::runtime_error {
 public:
  TermExprError(const std::string& what, size_t position);
  size_t position() const { return position_; }

 private:
  size_t position_;
};

class TermExpr {
 public:
  // Parses `text` by the grammar above; throws TermExprError (position of the offending token)
  // for anything outside it (an unknown signal or function, a missing parenthesis, a non-number
  // exponent, trailing text, a non-finite number).
  static TermExpr Parse(const std::string& text);

  // The expression's value at one sample (may be non-finite for e.g. 1/0: the caller checks).
  double Eval(const TermSignals& s) const;
  // Eval at every row: out[i] = Eval(rows[i]), the same bits, evaluated a block of rows per
  // operation (the term search's many expressions on long records).
  void EvalRows(const std::vector<TermSignals>& rows, double* out) const;
  // The column form of EvalRows: n samples of each signal (a null column reads 0).
  struct Columns {
    const double *q = nullptr, *qd = nullptr, *qdd = nullptr, *tau_R = nullptr;
    const double *q_hip = nullptr, *q_knee = nullptr, *qd_hip = nullptr, *qd_knee = nullptr;
    const double* t = nullptr;
  };
  void EvalColumns(const Columns& c, size_t n, double* out) const;
  // The text it was parsed from.
  const std::string& text() const { return text_; }
  // True when the expression reads the signal `name` (one of the grammar's signals; another name
  // throws std::invalid_argument).
  bool Reads(const std::string& name) const;
  // A friction-like term: expr = f * sgn(qd) with f not reading qd's sign (f reads no qd, or reads it
  // only through abs): sgn(qd) a factor of the product (through products, numerators and negations),
  // or of every addend of a sum. The forward plant carries such a term as a per-step friction bound
  // value * f (dof_frictionloss; sim/plant_effects.h) instead of an applied force. `f` receives the
  // factor (the tree with sgn(qd) taken out, printed back as text): f * sgn(qd) is expr bit for bit.
  bool FrictionLike(TermExpr* f = nullptr) const;

  struct Node;     // the parse tree (term_expr.cc)
  struct Program;  // the tree compiled to a flat postfix program (term_expr.cc)

 private:
  std::string text_;
  std::shared_ptr<const Node> root_;
  std::shared_ptr<const Program> program_;
  unsigned reads_ = 0;  // bit i: the expression reads the grammar's i-th signal
};

// The parsed expression of `text`, parsed once per text and kept (thread-safe; the reference stays
// valid): the closed forms of model files' terms evaluate through it. Throws TermExprError as Parse.
const TermExpr& CachedTermExpr(const std::string& text);

}  // namespace exotwin
