#include "diagnosis/generate.h"

#include <algorithm>
#include <cmath>

#include "formats/csv_table.h"
#include "diagnosis/effects.h"
#include "diagnosis/predict.h"
#include "diagnosis/fit_families.h"
#include "model/effect_families.h"
#include "model/term_expr.h"
#include "core/error.h"
#include "core/rng.h"
#include "core/units.h"
#include "sim/plant.h"

namespace exotwin {

namespace {

// The families the registry holds now that generate may hide (FitFamily::draw), in its order.
std::vector<std::string> DrawnFamilies() {
  std::vector<std::string> names;
  for (const FitFamily& f : FitFamilies())
    if (f.draw) names.push_back(f.family->name);
  return names;
}

}  // namespace

const std::vector<std::string>& AllEffectNames() {
  static const std::vector<std::string> k = DrawnFamilies();
  return k;
}

namespace {

const char* kEmgChannels[] = {"GMAX", "RF", "VM", "ST", "GAS"};
struct Harmonic {
  double amp, omega, phase;
};

}  // namespace

Effect DrawEffect(Rng& rng, const std::string& name, int joint, bool one_joint) {
  const FitFamily* family = FindFitFamily(name);
  if (!family || !family->draw) throw InputError("generate: unknown effect '" + name + "'");
  Effect e = family->draw(rng, joint, one_joint);
  e.name = name;
  e.joint = joint == 0 ? "hip" : "knee";
  e.unit = family->family->unit;
  return e;
}

GeneratedData GenerateMeasured(const LegParams& params, const GenerateOptions& opt) {
  if (!(opt.duration > 2.0 && opt.duration <= 7200.0))
    throw InputError("--duration: " + std::to_string(opt.duration) + " s, expected 2 .. 7200 s");
  if (!(opt.rate >= 100.0 && opt.rate <= 10000.0))
    throw InputError("--rate: " + std::to_string(opt.rate) + " Hz, expected 100 .. 10000 Hz");
  if (opt.effects < 0 || opt.effects > 3)
    throw InputError("--effects: " + std::to_string(opt.effects) + ", expected 0 .. 3");
  if (!opt.joint.empty() && opt.joint != "hip" && opt.joint != "knee")
    throw InputError("--joint: '" + opt.joint + "', expected hip or knee");
  const bool one = params.one_joint.has_value();
  if (one && opt.joint == "hip")
    throw InputError("--joint: 'hip' for a one-joint model file, expected knee (its one joint)");
  const std::vector<std::string> drawn = DrawnFamilies();
  std::vector<std::string> pool = opt.allowed.empty() ? drawn : opt.allowed;
  for (const auto& n : pool)
    if (std::find(drawn.begin(), drawn.end(), n) == drawn.end())
      throw InputError("--effect: unknown effect '" + n + "'");
  if (static_cast<int>(pool.size()) < opt.effects)
    throw InputError("--effects: " + std::to_string(opt.effects) + " distinct effects from " +
                     std::to_string(pool.size()) + " allowed names");

  for (const Effect& e : opt.terms) {
    const std::string what = "--term \"" + e.expr + "\"";
    try {
      TermExpr::Parse(e.expr);
    } catch (const TermExprError& x) {
      throw InputError(what + ": " + x.what() + " of the expression");
    }
    if (e.joint != "knee" && (one || e.joint != "hip"))
      throw InputError(what + ": joint '" + e.joint + "', expected " + (one ? "knee (the one-joint model's)" : "hip or knee"));
    if (!std::isfinite(e.value)) throw InputError(what + ": --value not finite");
    if (!e.stage.empty() && e.stage != "link" && e.stage != "sensor")
      throw InputError(what + ": --stage '" + e.stage + "', expected link or sensor");
  }
  NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> rng(opt.seed);
  GeneratedData g;
  g.truth = params;
  // Trajectory: three harmonics per joint, amplitudes summing to 70-100 % of the half range.
  Harmonic h[2][3];
  double centre[2], scale[2];
  for (int j = 0; j < 2; ++j) {
    // One joint: the hip held at 0 (the embedding, model/one_joint.h), the joint over its own range.
    const double lo = one ? (j == 0 ? 0.0 : kGenerateOneJointLo) : kGenerateJointLo[j];
    const double hi = one ? (j == 0 ? 0.0 : kGenerateOneJointHi) : kGenerateJointHi[j];
    centre[j] = 0.5 * (lo + hi);
    const double half = 0.5 * (hi - lo) * rng.Uniform(0.7, 1.0);
    double sum = 0;
    for (auto& k : h[j]) {
      k.amp = rng.Uniform(0.3, 1.0);
      k.omega = 2 * M_PI * rng.Uniform(0.3, 1.5);
      k.phase = rng.Uniform(-M_PI, M_PI);
      sum += k.amp;
    }
    scale[j] = half / sum;
  }
  // Effects.
  for (int k = 0; k < opt.effects; ++k) {
    const int pick = rng.Index(static_cast<int>(pool.size()));
    const std::string name = pool[pick];
    pool.erase(pool.begin() + pick);
    const int joint = one ? 1 : opt.joint.empty() ? rng.Index(2) : (opt.joint == "hip" ? 0 : 1);
    g.truth.effects.push_back(DrawEffect(rng, name, joint, one));
  }
  for (const Effect& e : opt.terms) g.truth.effects.push_back(e);
  // EMG activations: 0.02 + a (0.5 + 0.5 sin(w t + p))^2 V, a in 0.05-0.3 V, w in 0.1-0.8 Hz.
  struct Act { double a, w, p; } act[5];
  for (auto& a : act) a = {rng.Uniform(0.05, 0.3), 2 * M_PI * rng.Uniform(0.1, 0.8), rng.Uniform(-M_PI, M_PI)};
  g.torque_noise = rng.Uniform(0.02, 0.04);

  const size_t n = static_cast<size_t>(std::floor(opt.duration * opt.rate)) + 1;
  Kinematics kin;
  kin.t.resize(n);
  for (int j = 0; j < 2; ++j) kin.q[j].resize(n), kin.qd[j].resize(n), kin.qdd[j].resize(n);
  std::vector<double> emg[5];
  for (int c = 0; c < 5; ++c) emg[c].resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / opt.rate;
    kin.t[i] = t;
    for (int j = 0; j < 2; ++j) {
      double q = centre[j], qd = 0, qdd = 0;
      for (const auto& k : h[j]) {
        const double s = std::sin(k.omega * t + k.phase), c = std::cos(k.omega * t + k.phase);
        q += scale[j] * k.amp * s;
        qd += scale[j] * k.amp * k.omega * c;
        qdd -= scale[j] * k.amp * k.omega * k.omega * s;
      }
      kin.q[j][i] = q, kin.qd[j][i] = qd, kin.qdd[j][i] = qdd;
    }
    for (int c = 0; c < 5; ++c) {
      const double m = 0.5 + 0.5 * std::sin(act[c].w * t + act[c].p);
      emg[c][i] = (0.02 + act[c].a * m * m) * rng.Normal();
    }
  }
  for (int c = 0; c < 5; ++c) kin.emg[kEmgChannels[c]] = emg[c];
  kin.derivative_source = "analytic";

  Plant plant(ExowheelMjcfPath(g.truth.human.has_value()));
  plant.SetParams(g.truth);
  const Prediction truth = PredictTorque(plant, kin);

  // Measurement: encoder quantization, sensor noise and resolution.
  const double enc = 2 * M_PI / 524288.0, res = 0.005;
  MeasuredData& d = g.data;
  d.source = "generated(seed " + std::to_string(opt.seed) + ")";
  d.table.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  d.table.columns.assign(5, std::vector<double>(n));
  d.table.columns[0] = kin.t;
  std::vector<double>* col = d.table.columns.data();
  for (size_t i = 0; i < n; ++i) {
    col[1][i] = enc * std::round(kin.q[0][i] / enc);
    col[2][i] = enc * std::round(kin.q[1][i] / enc);
    col[3][i] = res * std::round((truth.tau_S[0][i] + g.torque_noise * rng.Normal()) / res);
    col[4][i] = res * std::round((truth.tau_S[1][i] + g.torque_noise * rng.Normal()) / res);
  }
  for (int c = 0; c < 5; ++c) {
    d.table.names.push_back(std::string("emg_") + kEmgChannels[c]);
    d.table.columns.push_back(emg[c]);
  }
  d.table.line_of_row.resize(n);
  for (size_t i = 0; i < n; ++i) d.table.line_of_row[i] = static_cast<int>(i) + 2;
  if (one) {  // the record of the one joint, embedded as a read one-joint record is
    d.one_joint = true;
    d.table = TableAsRecorded(d);
    EmbedOneJoint(&d.table);
  }
  d.BindRequired();
  return g;
}

void WriteGeneratedCsv(const GeneratedData& g, const std::string& path, uint64_t seed) {
  std::vector<const std::vector<double>*> cols;
  const CsvTable table = TableAsRecorded(g.data);
  for (const auto& c : table.columns) cols.push_back(&c);
  WriteCsv(path, table.names, cols,
           {"exotwin generate: synthetic measurement, seed " + std::to_string(seed) +
            " (the hidden effects are in the --truth file, not here)"});
}

}  // namespace exotwin
