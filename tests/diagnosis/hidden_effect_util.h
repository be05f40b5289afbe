// What the hidden-effect tests of the discrepancy loop share (diagnose_hidden_effect_test.cc,
// diagnose_one_joint_test.cc, diagnose_completeness_test.cc, term_search_test.cc): the model S1, the
// torque analysis alone, clean generated records and forms off the table hidden in them by hand, the
// diagnosed effect matching a hidden one, its relative error, and the seed counts the environment may
// override.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "model/leg_dynamics.h"

namespace exotwin {
namespace testing_hidden {

inline LegParams S1() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml"); }

// The torque analysis alone: what is named, not the forward simulation (step 6b).
inline DiagnoseOptions TorqueOnly() {
  DiagnoseOptions o;
  o.simulate = false;
  return o;
}

// A clean record of S1 at 500 Hz.
inline GeneratedData CleanRecord(uint64_t seed, double duration) {
  GenerateOptions g;
  g.seed = seed;
  g.effects = 0;
  g.duration = duration;
  g.rate = 500;
  return GenerateMeasured(S1(), g);
}

// A form off the table: the torque (N m) added to tau_R at a joint from that joint's q, qd, the rigid
// twin's tau_R and t (s from the record's start). Written here by hand, independent of the library.
using Form = std::function<double(double q, double qd, double tau_R, double t)>;

inline double Sgn(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// The form's torque at `joint` on every sample of `data`: the state from the record's own angles
// (DeriveKinematics), the rigid torque by the closed form of `p`.
inline std::vector<double> HiddenTorque(const LegParams& p, const MeasuredData& data, int joint, const Form& form) {
  const Kinematics k = DeriveKinematics(data);
  std::vector<double> h(k.t.size());
  for (size_t i = 0; i < h.size(); ++i) {
    const auto tau = ActuatorTorque(p, {k.q[0][i], k.q[1][i]}, {k.qd[0][i], k.qd[1][i]}, {k.qdd[0][i], k.qdd[1][i]});
    h[i] = form(k.q[joint][i], k.qd[joint][i], tau[joint], k.t[i] - k.t.front());
  }
  return h;
}

// The record with `form` added to tau_R at `joints` (the reading tau_S = -tau_R lowered by it).
inline void Hide(const LegParams& p, const std::vector<int>& joints, const Form& form, MeasuredData* data) {
  for (int j : joints) {
    const std::vector<double> h = HiddenTorque(p, *data, j, form);
    std::vector<double>& tau = data->column_at(j == 0 ? kColTauHip : kColTauKnee);
    for (size_t i = 0; i < tau.size(); ++i) tau[i] -= h[i];
  }
}

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
