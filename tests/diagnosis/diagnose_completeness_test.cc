// Stage 6c of diagnose (diagnosis/diagnose_completeness.cc): the table's model is "complete" on clean
// records (a correct model: >= 19 of 20 seeds, both joints) and "incomplete" where a torque off the
// table is hidden in the record (added by hand to the reading, tau_S -= value * expr since tau_S =
// -tau_R): a friction growing with the load, a Coulomb modulated by the angle, a friction fading as
// the drive warms up. The black box's ceiling sees what the table's model leaves of the load-dependent
// friction. The search for terms (term_search.h) then names the form: the final model is complete.
// The verdicts and ceilings of the table's and the final model are printed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "diagnosis/diagnose.h"
#include "tests/diagnosis/hidden_effect_util.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "model/leg_dynamics.h"

namespace exotwin {
namespace {

using testing_hidden::CleanRecord;
using testing_hidden::Form;
using testing_hidden::Hide;
using testing_hidden::S1;
using testing_hidden::Sgn;
using testing_hidden::TorqueOnly;

std::string Failed(const JointCompleteness& c) {
  std::string s;
  for (const auto& t : c.tests)
    if (!t.pass) s += " " + t.name;
  return s.empty() ? " -" : s;
}

TEST(DiagnoseCompleteness, CleanRecordsAreComplete) {
  const LegParams base = S1();
  int complete = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const GeneratedData g = CleanRecord(4000 + seed, 30);
    const Diagnosis d = Diagnose(base, g.data, TorqueOnly());
    const ModelAssessment& a = d.table_model;
    ASSERT_TRUE(a.completeness[0].assessed && a.completeness[1].assessed);
    const bool ok = a.completeness[0].complete && a.completeness[1].complete;
    complete += ok;
    std::printf("clean seed %2d: %s (hip%s, knee%s), effects %zu, rows %zu, step %zu, floor %.3g/%.3g N m, "
                "ceiling hip %.1f/%.1f knee %.1f/%.1f %%\n",
                static_cast<int>(seed), ok ? "complete" : "INCOMPLETE", Failed(a.completeness[0]).c_str(),
                Failed(a.completeness[1]).c_str(), d.effects.size(), a.completeness[1].rows, a.completeness[1].step,
                a.completeness[0].floor, a.completeness[1].floor, a.ceiling[0].named_pct, a.ceiling[0].black_box_pct,
                a.ceiling[1].named_pct, a.ceiling[1].black_box_pct);
    // The final model is the table's (no search for terms yet).
    EXPECT_EQ(d.final_model.completeness[1].complete, a.completeness[1].complete);
  }
  EXPECT_GE(complete, 19);
}

TEST(DiagnoseCompleteness, OffTableFormsAreIncomplete) {
  const LegParams base = S1();
  struct Case {
    const char* what;
    std::vector<int> joints;
    Form form;
  };
  const std::vector<Case> cases = {
      {"(0.3 + 0.06 |tau_R|) sgn(qd), both joints", {0, 1},
       [](double, double qd, double tau, double) { return (0.3 + 0.06 * std::abs(tau)) * Sgn(qd); }},
      {"1.0 (1 + 0.8 sin 3q) sgn(qd), knee", {1},
       [](double q, double qd, double, double) { return 1.0 * (1 + 0.8 * std::sin(3 * q)) * Sgn(qd); }},
      {"2 exp(-t / 15) sgn(qd), hip", {0}, [](double, double qd, double, double t) { return 2 * std::exp(-t / 15) * Sgn(qd); }},
  };
  for (const Case& c : cases)
    for (uint64_t seed = 1; seed <= 2; ++seed) {
      GeneratedData g = CleanRecord(5000 + seed, 30);
      Hide(base, c.joints, c.form, &g.data);
      const Diagnosis d = Diagnose(base, g.data, TorqueOnly());
      std::string named;
      for (const auto& e : d.effects)
        named += " " + e.effect.name + "(" + e.effect.joint + (e.effect.expr.empty() ? "" : ": " + e.effect.expr) + ")";
      for (int j : c.joints) {
        const JointCompleteness& v = d.table_model.completeness[j];
        const JointCeiling& ceil = d.table_model.ceiling[j];
        const JointCompleteness& vf = d.final_model.completeness[j];
        const JointCeiling& cf = d.final_model.ceiling[j];
        std::printf("%s, seed %d, %s: table %s (failed:%s), ceiling named %.1f %%, black box %.1f %%; named%s; "
                    "final %s (failed:%s), ceiling named %.1f %%, black box %.1f %%\n",
                    c.what, static_cast<int>(seed), j == 0 ? "hip" : "knee", v.complete ? "complete" : "incomplete",
                    Failed(v).c_str(), ceil.named_pct, ceil.black_box_pct, named.c_str(),
                    vf.complete ? "complete" : "incomplete", Failed(vf).c_str(), cf.named_pct, cf.black_box_pct);
        EXPECT_FALSE(v.complete) << c.what << " seed " << seed << " joint " << j;
        // The search for terms names the form (or one that stands for it): the final model is
        // complete and explains at least what the table's does.
        EXPECT_TRUE(vf.complete) << c.what << " seed " << seed << " joint " << j;
        EXPECT_GE(cf.named_pct, ceil.named_pct) << c.what;
        EXPECT_TRUE(ceil.done);
        // The black box adds to what the table's model explains (beyond noise) where the form is a
        // function of the state (not of time).
        if (c.joints.size() == 2) {
          EXPECT_GT(ceil.black_box_pct, ceil.named_pct + 1) << c.what;
        }
      }
    }
}

// The motion fit assesses its extended twin's torque residual alike: complete on a clean record,
// incomplete where the load-dependent friction is hidden.
TEST(DiagnoseCompleteness, MotionFitAssessesItsTwin) {
  const LegParams base = S1();
  DiagnoseOptions o;
  o.fit = DiagnoseFit::kMotion;
  GeneratedData g = CleanRecord(6001, 30);
  const Diagnosis clean = Diagnose(base, g.data, o);
  EXPECT_TRUE(clean.table_model.completeness[0].complete && clean.table_model.completeness[1].complete);
  Hide(base, {0, 1}, [](double, double qd, double tau, double) { return (0.3 + 0.06 * std::abs(tau)) * Sgn(qd); }, &g.data);
  const Diagnosis d = Diagnose(base, g.data, o);
  for (int j = 0; j < 2; ++j) {
    std::printf("motion fit, load-dependent friction, %s: %s (failed:%s); ceiling named %.1f %%, black box %.1f %%\n",
                j == 0 ? "hip" : "knee", d.table_model.completeness[j].complete ? "complete" : "incomplete",
                Failed(d.table_model.completeness[j]).c_str(), d.table_model.ceiling[j].named_pct,
                d.table_model.ceiling[j].black_box_pct);
    EXPECT_FALSE(d.table_model.completeness[j].complete) << j;
  }
}

}  // namespace
}  // namespace exotwin
