// What the hidden-effect tests of the discrepancy loop share (diagnose_hidden_effect_test.cc,
// diagnose_one_joint_test.cc): the diagnosed effect matching a hidden one, its relative error, and the
// seed counts the environment may override.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "diagnosis/diagnose.h"

namespace exotwin {
namespace testing_hidden {

// The integer environment variable `name`, or `def` when it is not set.
inline int EnvInt(const char* name, int def) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : def;
}

// The effect of `d` with the name and joint (and gravity axis) of `truth`; nullptr if none was named.
inline const DiagnosedEffect* Find(const Diagnosis& d, const Effect& truth) {
  for (const auto& e : d.effects)
    if (e.effect.name == truth.name && e.effect.joint == truth.joint &&
        (truth.name != "gravity_error" || e.effect.axis == truth.axis))
      return &e;
  return nullptr;
}

// Relative error of the diagnosed value against the truth (muscle activity: the worst true weight).
inline double ValueError(const Effect& truth, const Effect& found) {
  if (truth.name == "muscle_activity") {
    double worst = 0;
    for (const auto& f : truth.fields) {
      const auto it = found.fields.find(f.first);
      const double v = it == found.fields.end() ? 0.0 : it->second;
      worst = std::max(worst, std::abs(v - f.second) / std::abs(f.second));
    }
    return worst;
  }
  return std::abs(found.value - truth.value) / std::abs(truth.value);
}

}  // namespace testing_hidden
}  // namespace exotwin
