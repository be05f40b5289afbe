#include "model/term_expr.h"

#include <cctype>
#include <charconv>
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>

#include "model/effect_families.h"

namespace exotwin {

// The parse tree. Numbers keep their text (a factor of FrictionLike is printed back from the tree).
struct TermExpr::Node {
  enum Kind { kNum, kSignal, kNeg, kAdd, kSub, kMul, kDiv, kPow, kFunc };
  Kind kind = kNum;
  double value = 0;     // kNum: the number; kPow: the exponent
  std::string literal;  // kNum, kPow: the number as written
  int index = 0;        // kSignal: index into kSignals; kFunc: index into kFuncs
  std::shared_ptr<const Node> a, b;
};

// One operation of the postfix program; the stack holds doubles. The *K forms take their right
// operand (KSub, KDiv: their left one) from k, so a constant is not pushed.
enum class OpCode : unsigned char {
  kConst, kSignal, kNeg, kAdd, kSub, kMul, kDiv, kAddK, kSubK, kMulK, kDivK, kKSub, kKDiv,
  kSquare, kSqrt, kRecip, kPowK, kSgn, kAbs, kExp, kSin, kCos, kTanh, kPos
};
struct Op {
  OpCode code;
  int signal = 0;
  double k = 0;
};
struct TermExpr::Program {
  std::vector<Op> ops;
  int depth = 0;  // the stack's largest size
};

namespace {

using NodeP = std::shared_ptr<const TermExpr::Node>;
using Node = TermExpr::Node;

struct SignalDef {
  const char* name;
  double TermSignals::*member;
};
const SignalDef kSignals[] = {
    {"q", &TermSignals::q},           {"qd", &TermSignals::qd},         {"qdd", &TermSignals::qdd},
    {"tau_R", &TermSignals::tau_R},   {"q_hip", &TermSignals::q_hip},   {"q_knee", &TermSignals::q_knee},
    {"qd_hip", &TermSignals::qd_hip}, {"qd_knee", &TermSignals::qd_knee}, {"t", &TermSignals::t},
};
constexpr int kNumSignals = sizeof(kSignals) / sizeof(kSignals[0]);
constexpr int kQd = 1;  // kSignals' index of qd

const char* const kFuncs[] = {"sgn", "abs", "exp", "sin", "cos", "tanh", "pos"};
constexpr int kNumFuncs = sizeof(kFuncs) / sizeof(kFuncs[0]);
constexpr int kSgnFunc = 0, kAbsFunc = 1;
const OpCode kFuncOps[] = {OpCode::kSgn, OpCode::kAbs, OpCode::kExp, OpCode::kSin,
                           OpCode::kCos, OpCode::kTanh, OpCode::kPos};

int SignalIndex(const std::string& name) {
  for (int i = 0; i < kNumSignals; ++i)
    if (name == kSignals[i].name) return i;
  return -1;
}
int FuncIndex(const std::string& name) {
  for (int i = 0; i < kNumFuncs; ++i)
    if (name == kFuncs[i]) return i;
  return -1;
}

NodeP MakeNode(Node::Kind kind, NodeP a = nullptr, NodeP b = nullptr) {
  auto n = std::make_shared<Node>();
  n->kind = kind;
  n->a = std::move(a);
  n->b = std::move(b);
  return n;
}
NodeP MakeNum(double v, const std::string& literal) {
  auto n = std::make_shared<Node>();
  n->value = v;
  n->literal = literal;
  return n;
}

// Recursive descent over the grammar of term_expr.h; `pos_` is the next character.
class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  NodeP ParseAll() {
    NodeP root = Sum();
    SkipSpace();
    if (pos_ < s_.size()) Fail(std::string("unexpected '") + s_[pos_] + "' after the expression");
    return root;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw TermExprError(what, pos_); }
  [[noreturn]] void FailAt(const std::string& what, size_t at) const { throw TermExprError(what, at); }
  void SkipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool Accept(char c) {
    SkipSpace();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void Expect(char c) {
    if (!Accept(c)) Fail(std::string("expected '") + c + "'");
  }

  NodeP Sum() { return LeftAssociative('+', Node::kAdd, '-', Node::kSub, &Parser::Product); }
  NodeP Product() { return LeftAssociative('*', Node::kMul, '/', Node::kDiv, &Parser::Unary); }
  // operand ((c1 | c2) operand)*, associating to the left.
  NodeP LeftAssociative(char c1, Node::Kind k1, char c2, Node::Kind k2, NodeP (Parser::*operand)()) {
    NodeP l = (this->*operand)();
    for (;;) {
      if (Accept(c1)) l = MakeNode(k1, l, (this->*operand)());
      else if (Accept(c2)) l = MakeNode(k2, l, (this->*operand)());
      else return l;
    }
  }
  NodeP Unary() {
    if (Accept('-')) return MakeNode(Node::kNeg, Unary());
    return Power();
  }
  NodeP Power() {
    NodeP base = Atom();
    if (!Accept('^')) return base;
    SkipSpace();
    const size_t start = pos_;
    if (pos_ < s_.size() && (s_[pos_] == '-' || s_[pos_] == '+')) ++pos_;
    if (pos_ >= s_.size() || !(std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.'))
      FailAt("expected a number as the exponent of '^'", start);
    pos_ = start;
    auto n = std::make_shared<Node>(*Number(/*signed_ok=*/true));
    n->kind = Node::kPow;
    n->a = base;
    return n;
  }
  NodeP Atom() {
    SkipSpace();
    if (pos_ >= s_.size()) Fail("expected a number, a signal, a function or '(' (end of text)");
    const char c = s_[pos_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return Number(false);
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = pos_;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
      const std::string name = s_.substr(start, pos_ - start);
      const int f = FuncIndex(name);
      if (f >= 0) {
        Expect('(');
        auto n = std::make_shared<Node>();
        n->kind = Node::kFunc;
        n->index = f;
        n->a = Sum();
        Expect(')');
        return n;
      }
      const int sig = SignalIndex(name);
      if (sig >= 0) {
        auto n = std::make_shared<Node>();
        n->kind = Node::kSignal;
        n->index = sig;
        return n;
      }
      SkipSpace();
      const bool called = pos_ < s_.size() && s_[pos_] == '(';
      FailAt((called ? "unknown function '" : "unknown signal '") + name + "' (signals: q, qd, qdd, tau_R, " +
                 "q_hip, q_knee, qd_hip, qd_knee, t; functions: sgn, abs, exp, sin, cos, tanh, pos)",
             start);
    }
    if (Accept('(')) {
      NodeP inner = Sum();
      Expect(')');
      return inner;
    }
    Fail(std::string("unexpected '") + c + "': expected a number, a signal, a function or '('");
  }
  // digits [. digits] [e [+-] digits] (at least one digit before the exponent), optionally signed.
  NodeP Number(bool signed_ok) {
    const size_t start = pos_;
    auto digit = [&](size_t i) { return i < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i])); };
    if (signed_ok && pos_ < s_.size() && (s_[pos_] == '-' || s_[pos_] == '+')) ++pos_;
    size_t digits = 0;
    while (digit(pos_)) ++pos_, ++digits;
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      while (digit(pos_)) ++pos_, ++digits;
    }
    if (digits == 0) FailAt("expected a number", start);
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      size_t i = pos_ + 1;
      if (i < s_.size() && (s_[i] == '+' || s_[i] == '-')) ++i;
      if (digit(i)) {
        pos_ = i;
        while (digit(pos_)) ++pos_;
      }
    }
    const std::string literal = s_.substr(start, pos_ - start);
    const char* first = literal.c_str() + (literal[0] == '+' ? 1 : 0);
    double v = 0;
    const auto r = std::from_chars(first, literal.c_str() + literal.size(), v);
    if (r.ec != std::errc() || !std::isfinite(v))
      FailAt("the number " + literal + " is not a finite double", start);
    return MakeNum(v, literal);
  }

  const std::string& s_;
  size_t pos_ = 0;
};

unsigned ReadsMask(const Node& n) {
  unsigned m = n.kind == Node::kSignal ? 1u << n.index : 0u;
  if (n.a) m |= ReadsMask(*n.a);
  if (n.b) m |= ReadsMask(*n.b);
  return m;
}

double Apply(OpCode code, double x, double k) {
  switch (code) {
    case OpCode::kNeg: return -x;
    case OpCode::kAddK: return x + k;
    case OpCode::kSubK: return x - k;
    case OpCode::kMulK: return x * k;
    case OpCode::kDivK: return x / k;
    case OpCode::kKSub: return k - x;
    case OpCode::kKDiv: return k / x;
    case OpCode::kSquare: return x * x;
    case OpCode::kSqrt: return std::sqrt(x);
    case OpCode::kRecip: return 1.0 / x;
    case OpCode::kPowK: return std::pow(x, k);
    case OpCode::kSgn: return CoulombSign(x);
    case OpCode::kAbs: return std::fabs(x);
    case OpCode::kExp: return std::exp(x);
    case OpCode::kSin: return std::sin(x);
    case OpCode::kCos: return std::cos(x);
    case OpCode::kTanh: return std::tanh(x);
    case OpCode::kPos: return x > 0 ? 1.0 : 0.0;
    default: throw std::logic_error("TermExpr: not a unary operation");
  }
}
double Apply2(OpCode code, double x, double y) {
  switch (code) {
    case OpCode::kAdd: return x + y;
    case OpCode::kSub: return x - y;
    case OpCode::kMul: return x * y;
    case OpCode::kDiv: return x / y;
    default: throw std::logic_error("TermExpr: not a binary operation");
  }
}

OpCode PowOp(double exponent) {
  if (exponent == 2) return OpCode::kSquare;
  if (exponent == 0.5) return OpCode::kSqrt;
  if (exponent == -1) return OpCode::kRecip;
  return OpCode::kPowK;
}

// Compiles a tree to postfix: a subtree that reads no signal becomes one constant (evaluated by the
// same operations, so the same bits); a constant operand of + - * / is folded into the operation.
class Compiler {
 public:
  explicit Compiler(TermExpr::Program* p) : p_(p) {}

  void Emit(const Node& n) {
    if (ReadsMask(n) == 0) return Push({OpCode::kConst, 0, Constant(n)});
    switch (n.kind) {
      case Node::kSignal: return Push({OpCode::kSignal, n.index, 0});
      case Node::kNeg: Emit(*n.a); return Same({OpCode::kNeg});
      case Node::kFunc: Emit(*n.a); return Same({kFuncOps[n.index]});
      case Node::kPow:
        Emit(*n.a);
        if (n.value != 1) Same({PowOp(n.value), 0, n.value});  // x^1 = x exactly
        return;
      default: return Binary(n);
    }
  }

 private:
  void Binary(const Node& n) {
    static const OpCode kPlain[] = {OpCode::kAdd, OpCode::kSub, OpCode::kMul, OpCode::kDiv};
    static const OpCode kRightK[] = {OpCode::kAddK, OpCode::kSubK, OpCode::kMulK, OpCode::kDivK};
    // a + b = b + a and a * b = b * a exactly; k - x and k / x have their own operations.
    static const OpCode kLeftK[] = {OpCode::kAddK, OpCode::kKSub, OpCode::kMulK, OpCode::kKDiv};
    const int i = n.kind - Node::kAdd;
    if (ReadsMask(*n.b) == 0) {
      Emit(*n.a);
      return Same({kRightK[i], 0, Constant(*n.b)});
    }
    if (ReadsMask(*n.a) == 0) {
      Emit(*n.b);
      return Same({kLeftK[i], 0, Constant(*n.a)});
    }
    Emit(*n.a);
    Emit(*n.b);
    p_->ops.push_back({kPlain[i]});
    --size_;
  }
  void Push(const Op& op) {
    p_->ops.push_back(op);
    if (++size_ > p_->depth) p_->depth = size_;
  }
  void Same(const Op& op) { p_->ops.push_back(op); }  // replaces the top of the stack

  // A signal-free subtree's value by the program's own operations.
  static double Constant(const Node& n) {
    switch (n.kind) {
      case Node::kNum: return n.value;
      case Node::kNeg: return Apply(OpCode::kNeg, Constant(*n.a), 0);
      case Node::kFunc: return Apply(kFuncOps[n.index], Constant(*n.a), 0);
      case Node::kPow: return n.value == 1 ? Constant(*n.a) : Apply(PowOp(n.value), Constant(*n.a), n.value);
      case Node::kAdd: return Apply2(OpCode::kAdd, Constant(*n.a), Constant(*n.b));
      case Node::kSub: return Apply2(OpCode::kSub, Constant(*n.a), Constant(*n.b));
      case Node::kMul: return Apply2(OpCode::kMul, Constant(*n.a), Constant(*n.b));
      case Node::kDiv: return Apply2(OpCode::kDiv, Constant(*n.a), Constant(*n.b));
      default: throw std::logic_error("TermExpr: a signal in a constant");
    }
  }

  TermExpr::Program* p_;
  int size_ = 0;
};

constexpr size_t kBlockRows = 256;

// x[r] = Apply(op, x[r]) for r < n, the switch outside the loop.
void MapBlock(const Op& op, double* x, size_t n) {
  const double k = op.k;
  auto map = [&](auto f) {
    for (size_t r = 0; r < n; ++r) x[r] = f(x[r]);
  };
  switch (op.code) {
    case OpCode::kNeg: return map([](double v) { return -v; });
    case OpCode::kAddK: return map([k](double v) { return v + k; });
    case OpCode::kSubK: return map([k](double v) { return v - k; });
    case OpCode::kMulK: return map([k](double v) { return v * k; });
    case OpCode::kDivK: return map([k](double v) { return v / k; });
    case OpCode::kKSub: return map([k](double v) { return k - v; });
    case OpCode::kKDiv: return map([k](double v) { return k / v; });
    case OpCode::kSquare: return map([](double v) { return v * v; });
    case OpCode::kAbs: return map([](double v) { return std::fabs(v); });
    case OpCode::kSgn: return map([](double v) { return CoulombSign(v); });
    case OpCode::kPos: return map([](double v) { return v > 0 ? 1.0 : 0.0; });
    default: return map([&op](double v) { return Apply(op.code, v, op.k); });  // the library's functions
  }
}

// Runs the program on n <= kBlockRows samples at once: the stack holds a column of n values per slot; load(i, col)
// writes signal i's n values into col.
template <typename Load>
void RunBlock(const TermExpr::Program& p, size_t n, double* stack, Load load, double* out) {
  int top = -1;  // the top slot of the stack
  auto col = [&](int slot) { return stack + static_cast<size_t>(slot) * kBlockRows; };
  for (const Op& op : p.ops) {
    switch (op.code) {
      case OpCode::kConst: {
        double* c = col(++top);
        for (size_t r = 0; r < n; ++r) c[r] = op.k;
        break;
      }
      case OpCode::kSignal: load(op.signal, col(++top)); break;
      case OpCode::kAdd: case OpCode::kSub: case OpCode::kMul: case OpCode::kDiv: {
        double* x = col(top - 1);
        const double* y = col(top--);
        switch (op.code) {
          case OpCode::kAdd: for (size_t r = 0; r < n; ++r) x[r] += y[r]; break;
          case OpCode::kSub: for (size_t r = 0; r < n; ++r) x[r] -= y[r]; break;
          case OpCode::kMul: for (size_t r = 0; r < n; ++r) x[r] *= y[r]; break;
          default: for (size_t r = 0; r < n; ++r) x[r] /= y[r]; break;
        }
        break;
      }
      default: MapBlock(op, col(top), n);
    }
  }
  for (size_t r = 0; r < n; ++r) out[r] = col(0)[r];
}

template <typename Load>
void RunRows(const TermExpr::Program* p, size_t n, Load load, double* out) {
  if (!p) {
    for (size_t r = 0; r < n; ++r) out[r] = 0;
    return;
  }
  std::vector<double> stack(static_cast<size_t>(p->depth) * kBlockRows);
  for (size_t r0 = 0; r0 < n; r0 += kBlockRows) {
    const size_t m = std::min(kBlockRows, n - r0);
    RunBlock(*p, m, stack.data(), [&](int signal, double* c) { load(signal, r0, m, c); }, out + r0);
  }
}

bool IsSgnQd(const Node& n) {
  return n.kind == Node::kFunc && n.index == kSgnFunc && n.a->kind == Node::kSignal && n.a->index == kQd;
}
bool IsOne(const NodeP& n) { return n->kind == Node::kNum && n->value == 1; }

// The factor f of a friction-like tree: the tree with its sgn(qd) replaced by 1 (and the product by 1
// dropped), where the path to sgn(qd) runs through products, the numerators of quotients and
// negations only, or a sum/difference of such trees. Then tree = f * sgn(qd) with the same bits: a
// product or quotient by +-1 is exact and commutes with rounding. Null where the tree is not of that
// form.
NodeP SgnFactor(const NodeP& n) {
  if (IsSgnQd(*n)) return MakeNum(1, "1");
  switch (n->kind) {
    case Node::kNeg: {
      NodeP fa = SgnFactor(n->a);
      return fa ? MakeNode(Node::kNeg, fa) : nullptr;
    }
    case Node::kMul: {
      if (NodeP fa = SgnFactor(n->a)) return IsOne(fa) ? n->b : MakeNode(Node::kMul, fa, n->b);
      if (NodeP fb = SgnFactor(n->b)) return IsOne(fb) ? n->a : MakeNode(Node::kMul, n->a, fb);
      return nullptr;
    }
    case Node::kDiv: {
      NodeP fa = SgnFactor(n->a);
      return fa ? MakeNode(Node::kDiv, fa, n->b) : nullptr;
    }
    case Node::kAdd: case Node::kSub: {
      NodeP fa = SgnFactor(n->a), fb = SgnFactor(n->b);
      return fa && fb ? MakeNode(n->kind, fa, fb) : nullptr;
    }
    default: return nullptr;
  }
}

// True when qd is read anywhere but inside abs().
bool ReadsQdOutsideAbs(const Node& n) {
  if (n.kind == Node::kFunc && n.index == kAbsFunc) return false;
  if (n.kind == Node::kSignal) return n.index == kQd;
  return (n.a && ReadsQdOutsideAbs(*n.a)) || (n.b && ReadsQdOutsideAbs(*n.b));
}

// The tree as text that parses back to the same tree (parentheses where precedence or the left
// association requires them).
int Precedence(const Node& n) {
  switch (n.kind) {
    case Node::kAdd: case Node::kSub: return 1;
    case Node::kMul: case Node::kDiv: return 2;
    case Node::kNeg: return 3;
    case Node::kPow: return 4;
    default: return 5;
  }
}
std::string Print(const Node& n);
std::string Wrap(const Node& n, int min_precedence) {
  return Precedence(n) >= min_precedence ? Print(n) : "(" + Print(n) + ")";
}
std::string Print(const Node& n) {
  static const char* const kOps[] = {" + ", " - ", " * ", " / "};
  switch (n.kind) {
    case Node::kNum: return n.literal;
    case Node::kSignal: return kSignals[n.index].name;
    case Node::kFunc: return std::string(kFuncs[n.index]) + "(" + Print(*n.a) + ")";
    case Node::kNeg: return "-" + Wrap(*n.a, 3);
    case Node::kPow: return Wrap(*n.a, 5) + "^" + n.literal;
    default: {
      const int p = Precedence(n);
      return Wrap(*n.a, p) + kOps[n.kind - Node::kAdd] + Wrap(*n.b, p + 1);
    }
  }
}

}  // namespace

TermExprError::TermExprError(const std::string& what, size_t position)
    : std::runtime_error(what + " at position " + std::to_string(position)), position_(position) {}

TermExpr TermExpr::Parse(const std::string& text) {
  TermExpr e;
  e.text_ = text;
  e.root_ = Parser(text).ParseAll();
  e.reads_ = ReadsMask(*e.root_);
  auto program = std::make_shared<Program>();
  Compiler(program.get()).Emit(*e.root_);
  e.program_ = program;
  return e;
}

double TermExpr::Eval(const TermSignals& s) const {
  if (!program_) return 0;
  constexpr int kSmall = 32;
  double small[kSmall] = {0};
  std::vector<double> large;
  double* st = small;
  if (program_->depth > kSmall) {
    large.resize(program_->depth);
    st = large.data();
  }
  int top = -1;
  for (const Op& op : program_->ops) {
    switch (op.code) {
      case OpCode::kConst: st[++top] = op.k; break;
      case OpCode::kSignal: st[++top] = s.*kSignals[op.signal].member; break;
      case OpCode::kAdd: case OpCode::kSub: case OpCode::kMul: case OpCode::kDiv:
        st[top - 1] = Apply2(op.code, st[top - 1], st[top]);
        --top;
        break;
      default: st[top] = Apply(op.code, st[top], op.k);
    }
  }
  return st[0];
}

void TermExpr::EvalRows(const std::vector<TermSignals>& rows, double* out) const {
  RunRows(program_.get(), rows.size(),
          [&](int signal, size_t r0, size_t m, double* c) {
            const auto member = kSignals[signal].member;
            for (size_t r = 0; r < m; ++r) c[r] = rows[r0 + r].*member;
          },
          out);
}

void TermExpr::EvalColumns(const Columns& cols, size_t n, double* out) const {
  const double* const by_signal[kNumSignals] = {cols.q,     cols.qd,     cols.qdd,     cols.tau_R, cols.q_hip,
                                                cols.q_knee, cols.qd_hip, cols.qd_knee, cols.t};
  RunRows(program_.get(), n,
          [&](int signal, size_t r0, size_t m, double* c) {
            const double* src = by_signal[signal];
            for (size_t r = 0; r < m; ++r) c[r] = src ? src[r0 + r] : 0.0;
          },
          out);
}

bool TermExpr::Reads(const std::string& name) const {
  const int i = SignalIndex(name);
  if (i < 0) throw std::invalid_argument("TermExpr::Reads: '" + name + "' is not a signal of the grammar");
  return (reads_ >> i) & 1u;
}

const TermExpr& CachedTermExpr(const std::string& text) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<const TermExpr>> parsed;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = parsed.find(text);
  if (it == parsed.end()) it = parsed.emplace(text, std::make_unique<const TermExpr>(TermExpr::Parse(text))).first;
  return *it->second;
}

bool TermExpr::FrictionLike(TermExpr* f) const {
  if (!root_) return false;
  NodeP factor = SgnFactor(root_);
  if (!factor || ReadsQdOutsideAbs(*factor)) return false;
  if (f) *f = Parse(Print(*factor));
  return true;
}

}  // namespace exotwin
