// The term grammar (model/term_expr.h): every signal, function and operator against its closed form
// written out here with the C library, precedence and association, the positions of parse errors,
// Reads, FrictionLike (the factor f of f * sgn(qd) with the same bits), and the batch evaluators
// against Eval.
#include "model/term_expr.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace exotwin {
namespace {

TermSignals Sample() {
  TermSignals s;
  s.q = 0.7, s.qd = -1.3, s.qdd = 2.9, s.tau_R = -4.25;
  s.q_hip = 0.35, s.q_knee = -0.6, s.qd_hip = 0.8, s.qd_knee = -2.1, s.t = 3.5;
  return s;
}

double Eval(const std::string& text, const TermSignals& s = Sample()) { return TermExpr::Parse(text).Eval(s); }

TEST(TermExpr, EverySignalReadsItsMember) {
  const TermSignals s = Sample();
  EXPECT_EQ(Eval("q"), s.q);
  EXPECT_EQ(Eval("qd"), s.qd);
  EXPECT_EQ(Eval("qdd"), s.qdd);
  EXPECT_EQ(Eval("tau_R"), s.tau_R);
  EXPECT_EQ(Eval("q_hip"), s.q_hip);
  EXPECT_EQ(Eval("q_knee"), s.q_knee);
  EXPECT_EQ(Eval("qd_hip"), s.qd_hip);
  EXPECT_EQ(Eval("qd_knee"), s.qd_knee);
  EXPECT_EQ(Eval("t"), s.t);
}

TEST(TermExpr, FunctionsAgainstTheLibrary) {
  const TermSignals s = Sample();
  EXPECT_EQ(Eval("sgn(qd)"), -1.0);
  EXPECT_EQ(Eval("sgn(q)"), 1.0);
  EXPECT_EQ(Eval("sgn(q - 0.7)"), 0.0);  // coulomb_friction's sign: 0 at 0
  EXPECT_EQ(Eval("abs(tau_R)"), 4.25);
  EXPECT_EQ(Eval("exp(q)"), std::exp(s.q));
  EXPECT_EQ(Eval("sin(qdd)"), std::sin(s.qdd));
  EXPECT_EQ(Eval("cos(qd)"), std::cos(s.qd));
  EXPECT_EQ(Eval("tanh(qd / 0.1)"), std::tanh(s.qd / 0.1));
  EXPECT_EQ(Eval("pos(q)"), 1.0);
  EXPECT_EQ(Eval("pos(qd)"), 0.0);
  EXPECT_EQ(Eval("pos(q - 0.7)"), 0.0);  // 1 only where x > 0
  EXPECT_EQ(Eval("exp(-t / 14.2) * sgn(qd)"), -std::exp(-s.t / 14.2));
}

TEST(TermExpr, OperatorsAndPowers) {
  const TermSignals s = Sample();
  EXPECT_EQ(Eval("q + qd"), s.q + s.qd);
  EXPECT_EQ(Eval("q - qd"), s.q - s.qd);
  EXPECT_EQ(Eval("q * qd"), s.q * s.qd);
  EXPECT_EQ(Eval("q / qd"), s.q / s.qd);
  EXPECT_EQ(Eval("-q"), -s.q);
  EXPECT_EQ(Eval("qd^2"), s.qd * s.qd);
  EXPECT_EQ(Eval("q^0.5"), std::sqrt(s.q));
  EXPECT_EQ(Eval("qd^-1"), 1.0 / s.qd);
  EXPECT_EQ(Eval("qd^1"), s.qd);
  EXPECT_EQ(Eval("qd^3"), std::pow(s.qd, 3.0));
  EXPECT_EQ(Eval("q^1.5"), std::pow(s.q, 1.5));
  EXPECT_EQ(Eval("qdd ^ 2.5e-1"), std::pow(s.qdd, 0.25));
  // Constants on either side and signal-free subtrees (folded when compiled: the same bits).
  EXPECT_EQ(Eval("3 - q"), 3 - s.q);
  EXPECT_EQ(Eval("3 / q"), 3 / s.q);
  EXPECT_EQ(Eval("2 * 3 * q"), 6 * s.q);
  EXPECT_EQ(Eval("exp(1) * q + sin(2)^2"), std::exp(1.0) * s.q + std::sin(2.0) * std::sin(2.0));
  EXPECT_EQ(Eval("(1 + 2) / 4"), 0.75);
  // Numbers as written.
  EXPECT_EQ(Eval("1.5e-3"), 1.5e-3);
  EXPECT_EQ(Eval(".5"), 0.5);
  EXPECT_EQ(Eval("2."), 2.0);
  EXPECT_EQ(Eval("1E2"), 100.0);
  EXPECT_EQ(Eval("  \tq*\n2 "), 2 * s.q);
  EXPECT_TRUE(std::isinf(Eval("1 / (q - 0.7)")));  // non-finite values are the caller's to check
}

TEST(TermExpr, PrecedenceAndAssociation) {
  const TermSignals s = Sample();
  EXPECT_EQ(Eval("-q^2"), -(s.q * s.q));
  EXPECT_EQ(Eval("-qd^2"), -(s.qd * s.qd));
  EXPECT_EQ(Eval("2*q+1"), 2 * s.q + 1);
  EXPECT_EQ(Eval("1+2*q"), 1 + 2 * s.q);
  EXPECT_EQ(Eval("(1+2)*q"), 3 * s.q);
  EXPECT_EQ(Eval("q/qd/qdd"), (s.q / s.qd) / s.qdd);
  EXPECT_EQ(Eval("q-qd-qdd"), (s.q - s.qd) - s.qdd);
  EXPECT_EQ(Eval("q-(qd-qdd)"), s.q - (s.qd - s.qdd));
  EXPECT_EQ(Eval("q*-qd"), s.q * -s.qd);
  EXPECT_EQ(Eval("--q"), s.q);
  EXPECT_EQ(Eval("2*q^2"), 2 * (s.q * s.q));
  EXPECT_EQ(Eval("(2*q)^2"), (2 * s.q) * (2 * s.q));
  EXPECT_EQ(Eval("q + qd * qdd - t / tau_R"), s.q + s.qd * s.qdd - s.t / s.tau_R);
}

// The error's position and that its message says what was expected.
void ExpectError(const std::string& text, size_t position, const std::string& piece) {
  try {
    TermExpr::Parse(text);
    ADD_FAILURE() << "no error for '" << text << "'";
  } catch (const TermExprError& e) {
    EXPECT_EQ(e.position(), position) << text << ": " << e.what();
    const std::string m = e.what();
    EXPECT_NE(m.find(piece), std::string::npos) << text << ": " << m;
    EXPECT_NE(m.find("position " + std::to_string(position)), std::string::npos) << m;
  }
}

TEST(TermExpr, ErrorsAtTheirPosition) {
  ExpectError("q + qx", 4, "unknown signal 'qx'");
  ExpectError("2 * foo(q)", 4, "unknown function 'foo'");
  ExpectError("sin(", 4, "expected a number, a signal, a function");
  ExpectError("sin(q", 5, "expected ')'");
  ExpectError("sin q", 4, "expected '('");
  ExpectError("q^qd", 2, "exponent");
  ExpectError("q^(2)", 2, "exponent");
  ExpectError("q^", 2, "exponent");
  ExpectError("q^2^2", 3, "unexpected '^'");
  ExpectError("abs(q))", 6, "unexpected ')'");
  ExpectError("", 0, "end of text");
  ExpectError("   ", 3, "end of text");
  ExpectError("1e999", 0, "1e999 is not a finite");
  ExpectError("2 * -1e999", 5, "not a finite");
  ExpectError("q^1e999", 2, "not a finite");
  ExpectError("2 q", 2, "unexpected 'q'");
  ExpectError("q + * qd", 4, "unexpected '*'");
  ExpectError("Q", 0, "unknown signal 'Q'");  // names as written
  ExpectError("(q + 1", 6, "expected ')'");
}

TEST(TermExpr, Reads) {
  const TermExpr e = TermExpr::Parse("abs(tau_R) * sgn(qd) + 0 * q_knee");
  EXPECT_TRUE(e.Reads("tau_R"));
  EXPECT_TRUE(e.Reads("qd"));
  EXPECT_TRUE(e.Reads("q_knee"));
  for (const char* other : {"q", "qdd", "q_hip", "qd_hip", "qd_knee", "t"}) EXPECT_FALSE(e.Reads(other)) << other;
  EXPECT_TRUE(TermExpr::Parse("exp(-t / 14.2)").Reads("t"));
  EXPECT_FALSE(TermExpr::Parse("2 + 3").Reads("t"));
  EXPECT_THROW(e.Reads("tau_S"), std::invalid_argument);
}

// Samples around and at qd = 0, both signs of everything.
std::vector<TermSignals> Grid() {
  std::vector<TermSignals> rows;
  for (int i = 0; i < 700; ++i) {
    TermSignals s;
    s.q = std::sin(0.37 * i) * 1.2;
    s.qd = i % 7 == 0 ? 0.0 : std::cos(0.53 * i) * 3;
    s.qdd = std::sin(1.1 * i + 0.3) * 20;
    s.tau_R = std::cos(0.21 * i) * 30 - 5;
    s.q_hip = std::sin(0.05 * i), s.q_knee = -std::cos(0.07 * i);
    s.qd_hip = std::sin(0.11 * i) * 2, s.qd_knee = std::cos(0.13 * i) * 2;
    s.t = 0.01 * i;
    rows.push_back(s);
  }
  return rows;
}

// FrictionLike: expr = f * sgn(qd) at every sample with the same bits, f reading qd only inside abs.
void ExpectFrictionLike(const std::string& text, const std::string& factor_text) {
  const TermExpr e = TermExpr::Parse(text);
  TermExpr f;
  ASSERT_TRUE(e.FrictionLike(&f)) << text;
  EXPECT_EQ(f.text(), factor_text) << text;
  for (const TermSignals& s : Grid()) {
    const double sg = s.qd > 0 ? 1.0 : (s.qd < 0 ? -1.0 : 0.0);
    ASSERT_EQ(e.Eval(s), f.Eval(s) * sg) << text << " at qd = " << s.qd;
  }
  EXPECT_TRUE(e.FrictionLike());  // without a factor
}

TEST(TermExpr, FrictionLike) {
  ExpectFrictionLike("abs(tau_R)*sgn(qd)", "abs(tau_R)");
  ExpectFrictionLike("sgn(qd)*exp(-t/14.2)", "exp(-t / 14.2)");
  ExpectFrictionLike("sgn(qd)", "1");
  ExpectFrictionLike("-sgn(qd)", "-1");
  ExpectFrictionLike("(0.3 + 0.06 * abs(tau_R)) * sgn(qd)", "0.3 + 0.06 * abs(tau_R)");
  ExpectFrictionLike("0.3 * sgn(qd) + 0.06 * abs(tau_R) * sgn(qd)", "0.3 + 0.06 * abs(tau_R)");
  ExpectFrictionLike("2 * sgn(qd) / (1 + q^2)", "2 / (1 + q^2)");
  ExpectFrictionLike("(1 + 0.8 * sin(3 * q)) * sgn(qd)", "1 + 0.8 * sin(3 * q)");
  ExpectFrictionLike("(0.5 + 1.5 * exp(-abs(qd) / 0.05)) * sgn(qd)", "0.5 + 1.5 * exp(-abs(qd) / 0.05)");
  ExpectFrictionLike("-(q_hip - q_knee)^2 * sgn(qd) * tau_R", "-(q_hip - q_knee)^2 * tau_R");
  ExpectFrictionLike("sgn(qd) - 2 * sgn(qd)", "1 - 2");
}

TEST(TermExpr, NotFrictionLike) {
  for (const char* text : {"qd*abs(qd)", "tau_R*abs(tau_R)", "qd", "sgn(q)", "sgn(qd) * qd", "q / sgn(qd)",
                           "sgn(qd) * sgn(qd)", "sgn(qd) + q", "sgn(qd)^3", "exp(sgn(qd))", "sgn(2 * qd)",
                           "tanh(qd / 0.01)", "sgn(qd) * pos(qd)"}) {
    TermExpr f = TermExpr::Parse("q");
    EXPECT_FALSE(TermExpr::Parse(text).FrictionLike(&f)) << text;
    EXPECT_EQ(f.text(), "q") << text;  // untouched
  }
  EXPECT_FALSE(TermExpr().FrictionLike());
}

TEST(TermExpr, BatchEvaluatorsGiveEvalsBits) {
  const std::vector<TermSignals> rows = Grid();
  std::vector<double> q, qd, qdd, tau, qh, qk, qdh, qdk, t;
  for (const auto& s : rows) {
    q.push_back(s.q), qd.push_back(s.qd), qdd.push_back(s.qdd), tau.push_back(s.tau_R);
    qh.push_back(s.q_hip), qk.push_back(s.q_knee), qdh.push_back(s.qd_hip), qdk.push_back(s.qd_knee);
    t.push_back(s.t);
  }
  TermExpr::Columns c;
  c.q = q.data(), c.qd = qd.data(), c.qdd = qdd.data(), c.tau_R = tau.data(), c.q_hip = qh.data();
  c.q_knee = qk.data(), c.qd_hip = qdh.data(), c.qd_knee = qdk.data(), c.t = t.data();
  // A deep one: 40 nested sums need a stack deeper than Eval's on-stack buffer.
  std::string deep = "q";
  for (int i = 0; i < 40; ++i) deep = "qd + (" + deep + ") * 0.5";
  deep = "t^2 - " + std::string(40, '(') + "q" + std::string(40, ')') + " + (q_hip + (q_knee + (qd_hip + " +
         deep + ")))";
  for (const std::string& text :
       {std::string("(0.3 + 0.06 * abs(tau_R)) * sgn(qd)"), std::string("-q^2 / (1 + qdd^2) - 3 / t"),
        std::string("pos(qd_knee) * exp(-t / 14.2) * cos(q_knee) + tanh(qd_hip / 0.1) * sin(q_hip)^0.5"),
        std::string("4 - 2^2"), std::string("qdd^-1 * 7 - 7 / qdd^1"), deep}) {
    const TermExpr e = TermExpr::Parse(text);
    std::vector<double> by_rows(rows.size()), by_columns(rows.size());
    e.EvalRows(rows, by_rows.data());
    e.EvalColumns(c, rows.size(), by_columns.data());
    for (size_t i = 0; i < rows.size(); ++i) {
      const double v = e.Eval(rows[i]);
      ASSERT_TRUE(v == by_rows[i] || (std::isnan(v) && std::isnan(by_rows[i]))) << text << " row " << i;
      ASSERT_TRUE(v == by_columns[i] || (std::isnan(v) && std::isnan(by_columns[i]))) << text << " row " << i;
    }
  }
  // The deep expression against its recursion written out.
  const TermSignals s = Sample();
  double inner = s.q;
  for (int i = 0; i < 40; ++i) inner = s.qd + inner * 0.5;
  EXPECT_EQ(TermExpr::Parse(deep).Eval(s), s.t * s.t - s.q + (s.q_hip + (s.q_knee + (s.qd_hip + inner))));
  // A null column reads 0.
  TermExpr::Columns only_q;
  only_q.q = q.data();
  std::vector<double> out(rows.size());
  TermExpr::Parse("q + 2 * t + 1").EvalColumns(only_q, rows.size(), out.data());
  for (size_t i = 0; i < rows.size(); ++i) ASSERT_EQ(out[i], q[i] + 1);
}

TEST(TermExpr, DefaultIsZero) {
  const TermExpr e;
  EXPECT_EQ(e.Eval(Sample()), 0.0);
  std::vector<double> out(3, 9.0);
  e.EvalRows(std::vector<TermSignals>(3), out.data());
  EXPECT_EQ(out, std::vector<double>(3, 0.0));
  EXPECT_EQ(TermExpr::Parse(" q ").text(), " q ");
}

}  // namespace
}  // namespace exotwin
