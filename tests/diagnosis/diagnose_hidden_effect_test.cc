// Hidden-effect tests of the discrepancy loop: generate data from a truth twin carrying an effect the
// diagnosis is not told about, and require that diagnose names it (name, joint, value within 15 %)
// and that the extended twin gains >= 50 % on held-out data; pairs; no effect on clean data.
// EXOTWIN_DIAG_SEEDS sets the number of seeds per effect (default 8), EXOTWIN_DIAG_CLEAN the clean
// seeds (default 100). The detection table is printed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "tests/diagnosis/hidden_effect_util.h"
#include "formats/model_file.h"
#include "core/rng.h"

namespace exotwin {
namespace {

using testing_hidden::EnvInt;
using testing_hidden::Find;
using testing_hidden::ValueError;

using testing_hidden::S1;
using testing_hidden::TorqueOnly;

struct Row {
  int runs = 0, found = 0, exact = 0, ok = 0;
  double worst_err = 0, sum_err = 0, min_gain = 1e9, sum_gain = 0;
};

TEST(DiagnoseHiddenEffect, EverySingleEffectIsNamedMeasuredAndRemoved) {
  const LegParams base = S1();
  const int seeds = EnvInt("EXOTWIN_DIAG_SEEDS", 8);
  std::printf("%-18s %5s %6s %7s %9s %9s %9s %9s\n", "effect", "runs", "found", "only", "err_mean",
              "err_max", "gain_min", "gain_mean");
  int total = 0, total_ok = 0;
  const char* only = std::getenv("EXOTWIN_DIAG_ONLY");
  for (const std::string& name : AllEffectNames()) {
    if (only && name != only) continue;
    Row row;
    for (int s = 0; s < seeds; ++s) {
      GenerateOptions g;
      g.seed = 1000 + 37 * s + std::hash<std::string>{}(name) % 1000;
      g.effects = 1;
      g.allowed = {name};
      g.duration = 30;
      g.rate = 500;
      const GeneratedData data = GenerateMeasured(base, g);
      const Effect& truth = data.truth.effects[0];
      const Diagnosis d = Diagnose(base, data.data, TorqueOnly());
      const DiagnosedEffect* f = Find(d, truth);
      ++row.runs;
      const int j = truth.joint == "hip" ? 0 : 1;
      const double gain = d.joints[j].gain_pct;
      bool ok = false;
      if (f) {
        ++row.found;
        if (d.effects.size() == 1) ++row.exact;
        const double err = ValueError(truth, f->effect);
        row.sum_err += err;
        row.worst_err = std::max(row.worst_err, err);
        ok = err <= 0.15 && gain >= 50 && d.effects.size() == 1;
      }
      row.min_gain = std::min(row.min_gain, gain);
      row.sum_gain += gain;
      if (ok) ++row.ok;
      if (!ok) {
        std::printf("  miss seed %llu: truth %s(%s) = %g%s; found:", (unsigned long long)g.seed,
                    truth.name.c_str(), truth.joint.c_str(), truth.value,
                    truth.axis.empty() ? "" : (" axis " + truth.axis).c_str());
        for (const auto& e : d.effects)
          std::printf(" %s%s(%s)=%g", e.effect.name.c_str(), e.effect.axis.c_str(), e.effect.joint.c_str(),
                      e.effect.value);
        std::printf("; gain %.1f %%\n", gain);
      }
    }
    std::printf("%-18s %5d %5.0f%% %6.0f%% %8.1f%% %8.1f%% %8.1f%% %8.1f%%\n", name.c_str(), row.runs,
                100.0 * row.found / row.runs, 100.0 * row.exact / row.runs,
                row.found ? 100 * row.sum_err / row.found : 0.0, 100 * row.worst_err, row.min_gain,
                row.sum_gain / row.runs);
    total += row.runs;
    total_ok += row.ok;
    // Each effect: at least 7 of 8 seeds fully right (name, joint, only effect, value, gain).
    EXPECT_GE(row.ok * 8, row.runs * 7) << name;
  }
  std::printf("overall: %d / %d seeds fully right\n", total_ok, total);
}

TEST(DiagnoseHiddenEffect, PairsAreFound) {
  const LegParams base = S1();
  const int seeds = EnvInt("EXOTWIN_DIAG_PAIR_SEEDS", 20);
  int found_both = 0;
  for (int s = 0; s < seeds; ++s) {
    GenerateOptions g;
    g.seed = 5000 + s;
    g.effects = 2;
    g.duration = 40;
    g.rate = 500;
    const GeneratedData data = GenerateMeasured(base, g);
    const Diagnosis d = Diagnose(base, data.data, TorqueOnly());
    const bool both = Find(d, data.truth.effects[0]) && Find(d, data.truth.effects[1]);
    if (both) ++found_both;
    else {
      std::printf("  pair seed %d: truth %s(%s)=%g + %s(%s)=%g; found:", s + 5000,
                  data.truth.effects[0].name.c_str(), data.truth.effects[0].joint.c_str(),
                  data.truth.effects[0].value, data.truth.effects[1].name.c_str(),
                  data.truth.effects[1].joint.c_str(), data.truth.effects[1].value);
      for (const auto& e : d.effects)
        std::printf(" %s(%s)=%g", e.effect.name.c_str(), e.effect.joint.c_str(), e.effect.value);
      std::printf("\n");
    }
  }
  std::printf("pairs: both found in %d / %d seeds\n", found_both, seeds);
  EXPECT_GE(found_both * 10, seeds * 7);
}

// A sensor offset and Coulomb friction hidden together (issue 15: a hip offset beside knee friction
// was once named as a hip joint_stiffness with q0 = -214 rad). Both must be named, within 15 %, and
// no stiffness may stand in for the offset.
TEST(DiagnoseHiddenEffect, OffsetAndFrictionTogetherAreBothNamed) {
  const LegParams base = S1();
  const int seeds = EnvInt("EXOTWIN_DIAG_PAIR_SEEDS", 10);
  int both = 0;
  for (int s = 0; s < seeds; ++s) {
    Rng rng(7000 + s);
    const int oj = s % 2, fj = (s / 2) % 2;  // every joint combination
    LegParams truth = base;
    truth.effects.push_back({"sensor_offset", oj == 0 ? "hip" : "knee", rng.Sign() * rng.Uniform(0.2, 2.0), "N m", {}, ""});
    truth.effects.push_back({"coulomb_friction", fj == 0 ? "hip" : "knee", rng.Uniform(0.3, 1.5), "N m", {}, ""});
    GenerateOptions g;
    g.seed = 7000 + s;
    g.effects = 0;
    g.duration = 30;
    g.rate = 500;
    const Diagnosis d = Diagnose(base, GenerateMeasured(truth, g).data, TorqueOnly());
    const DiagnosedEffect* off = Find(d, truth.effects[0]);
    const DiagnosedEffect* fr = Find(d, truth.effects[1]);
    for (const auto& e : d.effects) EXPECT_NE(e.effect.name, "joint_stiffness") << "seed " << g.seed;
    const bool ok = off && fr && ValueError(truth.effects[0], off->effect) <= 0.15 &&
                    ValueError(truth.effects[1], fr->effect) <= 0.15;
    if (ok) ++both;
    else {
      std::printf("  offset+friction seed %llu: truth offset(%s)=%g coulomb(%s)=%g; found:",
                  (unsigned long long)g.seed, truth.effects[0].joint.c_str(), truth.effects[0].value,
                  truth.effects[1].joint.c_str(), truth.effects[1].value);
      for (const auto& e : d.effects)
        std::printf(" %s(%s)=%g", e.effect.name.c_str(), e.effect.joint.c_str(), e.effect.value);
      std::printf("\n");
    }
  }
  std::printf("offset + friction: both named in %d / %d seeds\n", both, seeds);
  EXPECT_GE(both * 10, seeds * 9);
}

TEST(DiagnoseHiddenEffect, NoEffectNamedOnCleanData) {
  const LegParams base = S1();
  const int seeds = EnvInt("EXOTWIN_DIAG_CLEAN", 100);
  int false_pos = 0, unexplained = 0;
  for (int s = 0; s < seeds; ++s) {
    GenerateOptions g;
    g.seed = 90000 + s;
    g.effects = 0;
    g.duration = 20;
    g.rate = 500;
    const Diagnosis d = Diagnose(base, GenerateMeasured(base, g).data, TorqueOnly());
    if (!d.effects.empty()) {
      ++false_pos;
      std::printf("  clean seed %d: named %s(%s) = %g\n", 90000 + s, d.effects[0].effect.name.c_str(),
                  d.effects[0].effect.joint.c_str(), d.effects[0].effect.value);
    }
    if (!d.unexplained.empty()) ++unexplained;
  }
  std::printf("clean data: false-positive rate %d / %d seeds, unexplained reported in %d\n", false_pos,
              seeds, unexplained);
  EXPECT_LE(false_pos * 100, seeds * 2);  // <= 2 %
}

}  // namespace
}  // namespace exotwin
