#include "controller/controller_config.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/units.h"
#include "protocol/messages.h"

namespace exotwin {

void ParseControllerSpec(const YamlContext& r, const YAML::Node& n, ControllerSpec* c, bool require_gains) {
  YamlCheckKeys(r, n, "controller", {"rate_hz", "kp", "kd", "feedforward", "torque_limit"});
  if (require_gains) {
    if (!n["kp"]) r.Fail("controller.kp", "missing, expected [hip, knee] (N m/rad)");
    if (!n["kd"]) r.Fail("controller.kd", "missing, expected [hip, knee] (N m s/rad)");
  }
  if (n["rate_hz"]) c->rate_hz = YamlNumber(r, n["rate_hz"], "controller.rate_hz", 100, 10000);
  if (n["kp"]) YamlNumberPair(r, n["kp"], "controller.kp", c->kp, 0, 1e5);
  if (n["kd"]) YamlNumberPair(r, n["kd"], "controller.kd", c->kd, 0, 1e4);
  if (n["feedforward"]) c->feedforward = YamlBool(r, n["feedforward"], "controller.feedforward");
  if (n["torque_limit"]) c->torque_limit = YamlNumber(r, n["torque_limit"], "controller.torque_limit", 1, 500);
}

namespace {
// 17 significant digits: the text reads back to the same double.
std::string Num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}
}  // namespace

std::string ControllerSpecYaml(const ControllerSpec& c) {
  return "controller: {rate_hz: " + Num(c.rate_hz) + ", kp: [" + Num(c.kp[0]) + ", " + Num(c.kp[1]) + "], kd: [" +
         Num(c.kd[0]) + ", " + Num(c.kd[1]) + "], feedforward: " + (c.feedforward ? "true" : "false") +
         ", torque_limit: " + Num(c.torque_limit) + "}\n";
}

namespace controller {

std::shared_ptr<const LegTrajectory> BuildReference(const ReferenceSpec& p, int trial) {
  std::shared_ptr<const LegTrajectory> inner;
  switch (p.kind) {
    case ReferenceKind::kGait: {
      GaitSpec g;
      g.stride_period_s = p.stride_period;
      // Winter's knee reaches +2 deg (hyperextension) in stance; the exoskeleton stops at 0, so
      // the pattern is shifted by -3 deg at the knee.
      g.knee_offset = -3.0 / kDegPerRad;  // the double nearest -3 pi / 180 (-3 * kRadPerDeg is 1 ulp off)
      inner = std::make_shared<GaitTrajectory>(GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath(), g));
      break;
    }
    case ReferenceKind::kExcitation: {
      const uint64_t seed = p.excitation_seed * 1000003ull + static_cast<uint64_t>(trial);
      std::shared_ptr<const JointTrajectory> hip, knee;
      if (p.moving_joint == "hip" || p.moving_joint == "both")
        hip = std::make_shared<HarmonicTrajectory>(HarmonicTrajectory::Design(ExcitationSpec::PaperHip(), seed));
      else
        hip = std::make_shared<HoldTrajectory>(p.hold_hip.value_or(M_PI / 2));
      if (p.moving_joint == "knee" || p.moving_joint == "both")
        knee = std::make_shared<HarmonicTrajectory>(HarmonicTrajectory::Design(ExcitationSpec::PaperKnee(), seed + 7));
      else
        knee = std::make_shared<HoldTrajectory>(p.hold_knee.value_or(-M_PI / 2));
      inner = std::make_shared<JointwiseTrajectory>(hip, knee);
      break;
    }
    case ReferenceKind::kHold:
      inner = std::make_shared<JointwiseTrajectory>(std::make_shared<HoldTrajectory>(p.hold_hip.value_or(0.3)),
                                                    std::make_shared<HoldTrajectory>(p.hold_knee.value_or(-0.5)));
      break;
    case ReferenceKind::kSamples:
      inner = std::make_shared<TabulatedTrajectory>(
          p.sample_dt, p.sample_hip, p.sample_knee,
          p.sample_loop ? TabulatedTrajectory::Extend::kLoop : TabulatedTrajectory::Extend::kHold, p.sample_cutoff);
      break;
  }
  if (p.ramp > 0) inner = std::make_shared<FadeInTrajectory>(inner, p.ramp);
  return inner;
}

ExoControllerConfig ExoConfigOf(const ControllerFile& f) {
  const ControllerSpec& s = f.controller;
  ExoControllerConfig c;
  c.rate_hz = s.rate_hz;
  c.hip = {s.kp[0], s.kd[0], s.torque_limit};
  c.knee = {s.kp[1], s.kd[1], s.torque_limit};
  c.feedforward = s.feedforward;
  c.model = f.model;
  c.estimator.sample_rate_hz = s.rate_hz;
  c.safety = SafetyConfig::Default();
  for (auto* lim : {&c.safety.hip, &c.safety.knee}) {
    lim->tau_sensor_max = std::min(115.0, f.driver_limit);
    lim->tau_cmd_max = s.torque_limit + 1e-6;
    lim->qd_max = 8.0;  // rad/s (460 deg/s): gait at 2 km/h peaks near 200 deg/s
  }
  return c;
}

namespace {

constexpr const char* kLumpedKeys[] = {"J1", "J2", "X1", "X2", "Y1", "Y2"};

LumpedParams ParseLumped(const YamlContext& r, const YAML::Node& n, const std::string& key) {
  YamlCheckKeys(r, n, key, {"J1", "J2", "X1", "X2", "Y1", "Y2"});
  double v[6];
  for (int i = 0; i < 6; ++i) {
    const std::string k = kLumpedKeys[i];
    if (!n[k]) r.Fail(key + "." + k, "missing, expected a number (kg m^2 or kg m)");
    v[i] = YamlNumber(r, n[k], key + "." + k, -1e3, 1e3);
  }
  LumpedParams p;
  p.J1 = v[0], p.J2 = v[1], p.X1 = v[2], p.X2 = v[3], p.Y1 = v[4], p.Y2 = v[5];
  return p;
}

void ParseModel(const YamlContext& r, const YAML::Node& n, LegParams* m) {
  YamlCheckKeys(r, n, "model", {"L1", "g", "exo", "human", "passive"});
  if (!n["L1"]) r.Fail("model.L1", "missing, expected the thigh length (m)");
  m->L1 = YamlNumber(r, n["L1"], "model.L1", 0.1, 1.0, "m");
  if (n["g"]) m->g = YamlNumber(r, n["g"], "model.g", 0, 20, "m/s^2");
  if (!n["exo"]) r.Fail("model.exo", "missing, expected {J1, J2, X1, X2, Y1, Y2}");
  m->exo = ParseLumped(r, n["exo"], "model.exo");
  if (n["human"]) m->human = ParseLumped(r, n["human"], "model.human");
  if (n["passive"])
    m->passive = YamlString(r, n["passive"], "model.passive", {"none", "riener1999"}) == "none" ? PassiveModel::kNone
                                                                                               : PassiveModel::kRiener1999;
}

void ParseReference(const YamlContext& r, const YAML::Node& n, ReferenceSpec* p) {
  YamlCheckKeys(r, n, "reference", {"kind", "stride_period", "moving_joint", "excitation_seed", "ramp", "hold", "samples"});
  if (n["kind"]) {
    const std::string k = YamlString(r, n["kind"], "reference.kind", {"gait", "excitation", "hold", "samples"});
    p->kind = k == "gait" ? ReferenceKind::kGait
              : k == "excitation" ? ReferenceKind::kExcitation
              : k == "hold"       ? ReferenceKind::kHold
                                  : ReferenceKind::kSamples;
  }
  if (p->kind == ReferenceKind::kSamples) {
    const YAML::Node m = n["samples"];
    if (!m || !m.IsMap()) r.Fail("reference.samples", "missing, expected {dt, loop, cutoff, hip: [...], knee: [...]}" + YamlLine(n));
    YamlCheckKeys(r, m, "reference.samples", {"dt", "loop", "cutoff", "hip", "knee"});
    p->sample_dt = YamlNumber(r, m["dt"], "reference.samples.dt", 1e-4, 1, "s");
    if (m["loop"]) p->sample_loop = YamlBool(r, m["loop"], "reference.samples.loop");
    if (m["cutoff"]) p->sample_cutoff = YamlNumber(r, m["cutoff"], "reference.samples.cutoff", 0.1, 1000, "Hz");
    for (const char* j : {"hip", "knee"}) {
      const YAML::Node a = m[j];
      const std::string key = std::string("reference.samples.") + j;
      if (!a || !a.IsSequence() || a.size() < 2) r.Fail(key, "expected a list of >= 2 angles (rad)" + (a ? YamlLine(a) : ""));
      std::vector<double>& out = std::string(j) == "hip" ? p->sample_hip : p->sample_knee;
      out.clear();
      for (size_t i = 0; i < a.size(); ++i) out.push_back(YamlNumber(r, a[i], key + "[" + std::to_string(i) + "]", -3.5, 3.5, "rad"));
    }
    if (p->sample_hip.size() != p->sample_knee.size())
      r.Fail("reference.samples", "hip and knee have " + std::to_string(p->sample_hip.size()) + " and " +
                                      std::to_string(p->sample_knee.size()) + " samples, expected the same number");
  }
  if (n["stride_period"]) p->stride_period = YamlNumber(r, n["stride_period"], "reference.stride_period", 0.5, 10, "s");
  if (n["moving_joint"])
    p->moving_joint = YamlString(r, n["moving_joint"], "reference.moving_joint", {"hip", "knee", "both"});
  if (n["excitation_seed"])
    p->excitation_seed = static_cast<uint64_t>(YamlNumber(r, n["excitation_seed"], "reference.excitation_seed", 0, 1e15));
  if (n["ramp"]) p->ramp = YamlNumber(r, n["ramp"], "reference.ramp", 0, 60, "s");
  if (const YAML::Node h = n["hold"]) {
    YamlCheckKeys(r, h, "reference.hold", {"hip", "knee"});
    if (h["hip"]) p->hold_hip = YamlNumber(r, h["hip"], "reference.hold.hip", -2.5, 2.5, "rad");
    if (h["knee"]) p->hold_knee = YamlNumber(r, h["knee"], "reference.hold.knee", -2.5, 2.5, "rad");
  }
}

std::string LumpedYaml(const LumpedParams& p) {
  return "{J1: " + Num(p.J1) + ", J2: " + Num(p.J2) + ", X1: " + Num(p.X1) + ", X2: " + Num(p.X2) + ", Y1: " +
         Num(p.Y1) + ", Y2: " + Num(p.Y2) + "}";
}


// The numbers of a HAL-3 controller file's `hal:` mapping: path below `hal`, the field, its range.
// Derived, not written (SetRateAndLimit from controller.rate_hz and hal.tau_max): hal.rate_hz,
// velocity.sample_rate_hz, assist.dt, assist.rls.dt, assist.tau_max.
struct HalNumber {
  const char* path;
  double* v;
  double lo, hi;
};

std::vector<HalNumber> HalNumbers(HalLoopConfig& c) {
  HalAssistConfig& a = c.assist;
  return {{"rms_window", &c.rms_window, 1e-3, 10},
          {"emg_fs", &c.emg_fs, 1, 1e5},
          {"tau_max", &c.tau_max, 1e-3, 500},
          {"status_timeout", &c.status_timeout, 1e-4, 10},
          {"velocity.velocity_cutoff_hz", &c.velocity.velocity_cutoff_hz, 0.01, 1e4},
          {"velocity.acceleration_cutoff_hz", &c.velocity.acceleration_cutoff_hz, 0.01, 1e4},
          {"impedance.actual.I", &c.impedance.actual.I, 0, 100},
          {"impedance.actual.B", &c.impedance.actual.B, -100, 100},
          {"impedance.actual.mgl", &c.impedance.actual.mgl, 0, 1000},
          {"impedance.actual.C", &c.impedance.actual.C, 0, 100},
          {"impedance.target.I", &c.impedance.target.I, 0, 100},
          {"impedance.target.B", &c.impedance.target.B, -100, 100},
          {"impedance.target.mgl", &c.impedance.target.mgl, 0, 1000},
          {"impedance.target.C", &c.impedance.target.C, 0, 100},
          {"impedance.coulomb_eps", &c.impedance.coulomb_eps, 1e-6, 100},
          {"assist.alpha_mu", &a.alpha_mu, 0, 10},
          {"assist.alpha_zeta", &a.alpha_zeta, 0, 10},
          {"assist.lambda1", &a.lambda1, 1e-3, 1e5},
          {"assist.lambda2", &a.lambda2, 1e-3, 1e5},
          {"assist.friction_C", &a.friction_C, 0, 100},
          {"assist.friction_eps", &a.friction_eps, 1e-6, 100},
          {"assist.emg.extensor.a", &a.emg.extensor.a, -1e9, 1e9},
          {"assist.emg.extensor.b", &a.emg.extensor.b, -1e6, 1e6},
          {"assist.emg.flexor.a", &a.emg.flexor.a, -1e9, 1e9},
          {"assist.emg.flexor.b", &a.emg.flexor.b, -1e6, 1e6},
          {"assist.emg.baseline_e", &a.emg.baseline_e, 0, 100},
          {"assist.emg.baseline_f", &a.emg.baseline_f, 0, 100},
          {"assist.rls.rho", &a.rls.rho, 0.5, 1},
          {"assist.rls.p0", &a.rls.p0, 1e-12, 1e300},
          {"assist.rls.p_max", &a.rls.p_max, 1e-12, 1e300},
          {"assist.rls.pf", &a.rls.pf, 1e-6, 1e6},
          {"assist.rls.R", &a.rls.R, -100, 100},
          {"assist.rls.mgl", &a.rls.mgl, 0, 1000},
          {"assist.rls.I0", &a.rls.I0, 1e-6, 100},
          {"assist.rls.D0", &a.rls.D0, -1e3, 1e3},
          {"assist.rls.K0", &a.rls.K0, -1e4, 1e4}};
}

struct HalFlag {
  const char* path;
  bool* v;
};

std::vector<HalFlag> HalFlags(HalLoopConfig& c) {
  return {{"assist.rls.gravity_in_input", &c.assist.rls.gravity_in_input},
          {"assist.rls.known_inertia", &c.assist.rls.known_inertia}};
}

struct HalInteger {
  const char* path;
  int* v;
  int lo, hi;
};

std::vector<HalInteger> HalIntegers(HalLoopConfig& c) {
  return {{"extensor_channel", &c.extensor_channel, 0, msg::kEmgChannels - 1},
          {"flexor_channel", &c.flexor_channel, 0, msg::kEmgChannels - 1},
          {"velocity.order", &c.velocity.order, 1, 8}};
}

// The node at `path` (dot-separated) below `n`; an undefined node when a mapping on the way is absent.
YAML::Node HalNode(const YAML::Node& n, const std::string& path) {
  if (!n.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const size_t dot = path.find('.');
  const YAML::Node c = n[path.substr(0, dot)];
  if (!c || dot == std::string::npos) return c;
  return HalNode(c, path.substr(dot + 1));
}

const std::vector<std::string>& HalKeysBelow(const std::string& prefix) {
  static const std::map<std::string, std::vector<std::string>> keys = [] {
    std::map<std::string, std::vector<std::string>> k;
    HalLoopConfig c;
    std::vector<std::string> paths = {"mode"};
    for (const HalNumber& f : HalNumbers(c)) paths.push_back(f.path);
    for (const HalFlag& f : HalFlags(c)) paths.push_back(f.path);
    for (const HalInteger& f : HalIntegers(c)) paths.push_back(f.path);
    for (const std::string& p : paths) {
      size_t from = 0, dot;
      std::string at;
      while (true) {
        dot = p.find('.', from);
        const std::string part = p.substr(from, dot == std::string::npos ? std::string::npos : dot - from);
        std::vector<std::string>& v = k[at];
        if (std::find(v.begin(), v.end(), part) == v.end()) v.push_back(part);
        if (dot == std::string::npos) break;
        at += (at.empty() ? "" : ".") + part;
        from = dot + 1;
      }
    }
    return k;
  }();
  static const std::vector<std::string> none;
  const auto it = keys.find(prefix);
  return it == keys.end() ? none : it->second;
}

// Every mapping below `n` (at `prefix`) holds known keys only.
void CheckHalKeys(const YamlContext& r, const YAML::Node& n, const std::string& prefix) {
  const std::string key = prefix.empty() ? "hal" : "hal." + prefix;
  if (!n.IsMap()) r.Fail(key, "expected a mapping" + YamlLine(n));
  const std::vector<std::string>& known = HalKeysBelow(prefix);
  YamlCheckKeys(r, n, key, std::set<std::string>(known.begin(), known.end()));
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    const std::string sub = prefix.empty() ? k : prefix + "." + k;
    if (!HalKeysBelow(sub).empty()) CheckHalKeys(r, kv.second, sub);
  }
}

// Reads the `hal:` mapping: every number is required (a HAL controller file is the loop's whole
// configuration, nothing assumed); rate-derived fields from controller.rate_hz.
HalLoopConfig ParseHal(const YamlContext& r, const YAML::Node& n, const ControllerSpec& ctrl) {
  CheckHalKeys(r, n, "");
  HalLoopConfig c;
  if (!n["mode"]) r.Fail("hal.mode", "missing, expected none | impedance | assist");
  const std::string mode = YamlString(r, n["mode"], "hal.mode", {"none", "impedance", "assist"});
  c.mode = mode == "none" ? HalMode::kNone : (mode == "assist" ? HalMode::kAssist : HalMode::kImpedance);
  for (const HalNumber& f : HalNumbers(c)) {
    const YAML::Node v = HalNode(n, f.path);
    if (!v) r.Fail(std::string("hal.") + f.path, "missing, expected a number");
    *f.v = YamlNumber(r, v, std::string("hal.") + f.path, f.lo, f.hi);
  }
  for (const HalInteger& f : HalIntegers(c)) {
    const YAML::Node v = HalNode(n, f.path);
    if (!v) r.Fail(std::string("hal.") + f.path, "missing, expected an integer");
    const double x = YamlNumber(r, v, std::string("hal.") + f.path, f.lo, f.hi);
    if (x != std::floor(x)) r.Fail(std::string("hal.") + f.path, "expected an integer" + YamlLine(v));
    *f.v = static_cast<int>(x);
  }
  for (const HalFlag& f : HalFlags(c)) {
    const YAML::Node v = HalNode(n, f.path);
    if (!v) r.Fail(std::string("hal.") + f.path, "missing, expected true or false");
    *f.v = YamlBool(r, v, std::string("hal.") + f.path);
  }
  if (c.tau_max > ctrl.torque_limit)
    r.Fail("hal.tau_max", Num(c.tau_max) + " N m is beyond controller.torque_limit " + Num(ctrl.torque_limit) + " N m");
  SetRateAndLimit(&c, ctrl.rate_hz);
  return c;
}

// The mapping at `prefix` of the `hal:` text, block style, in the order of HalKeysBelow; `leaf` holds
// each value's text by path.
void WriteHalMapping(std::ostream& o, const std::map<std::string, std::string>& leaf, const std::string& prefix,
                     int indent) {
  for (const std::string& k : HalKeysBelow(prefix)) {
    const std::string path = prefix.empty() ? k : prefix + "." + k;
    o << std::string(indent, ' ') << k << ":";
    if (HalKeysBelow(path).empty()) {
      o << " " << leaf.at(path) << "\n";
    } else {
      o << "\n";
      WriteHalMapping(o, leaf, path, indent + 2);
    }
  }
}

// The `hal:` mapping's entries (two-space indent) for `c`.
void WriteHal(std::ostream& o, HalLoopConfig c) {
  std::map<std::string, std::string> leaf;
  leaf["mode"] = HalModeName(c.mode);
  for (const HalNumber& f : HalNumbers(c)) leaf[f.path] = Num(*f.v);
  for (const HalFlag& f : HalFlags(c)) leaf[f.path] = *f.v ? "true" : "false";
  for (const HalInteger& f : HalIntegers(c)) leaf[f.path] = std::to_string(*f.v);
  WriteHalMapping(o, leaf, "", 2);
}
}  // namespace

ControllerFile ParseControllerFile(const std::string& text, const std::string& source) {
  const YamlContext r{source};
  const YAML::Node root = ParseYaml(text, source);
  if (!root || !root.IsMap()) throw InputError(source + ": expected a controller file (a YAML mapping with controller:, drivers:, model:, reference:)");
  if (root["device"])
    r.Fail("model", "a scenario's feed-forward model is computed by the twin from the subject; give the controller "
                    "file `exotwin serve` writes for it (OUT/controller.yaml)");
  YamlCheckKeys(r, root, "", {"controller", "drivers", "model", "reference", "trials", "hal"});
  ControllerFile f;
  f.source = source;
  if (!root["controller"]) r.Fail("controller", "missing, expected {rate_hz, kp, kd, feedforward, torque_limit}");
  const bool hal = static_cast<bool>(root["hal"]);
  ParseControllerSpec(r, root["controller"], &f.controller, !hal);
  if (hal) {
    for (const char* k : {"model", "reference"})
      if (root[k]) r.Fail(k, "a HAL-3 controller file (hal:) has no " + std::string(k) + YamlLine(root[k]));
    f.controller.feedforward = false;
  }
  if (const YAML::Node d = root["drivers"]) {
    YamlCheckKeys(r, d, "drivers", {"torque_limit"});
    if (d["torque_limit"]) f.driver_limit = YamlNumber(r, d["torque_limit"], "drivers.torque_limit", 1, 500, "N m");
  }
  if (!hal && f.controller.torque_limit > f.driver_limit)  // HAL-3: hal.tau_max is checked below
    r.Fail("controller.torque_limit", Num(f.controller.torque_limit) + " N m is beyond the drivers' range (drivers.torque_limit " +
                                          Num(f.driver_limit) + " N m)");
  if (root["model"]) ParseModel(r, root["model"], &f.model);
  else if (f.controller.feedforward) r.Fail("model", "missing, the feed-forward (controller.feedforward: true) needs the controller's model");
  if (root["reference"]) ParseReference(r, root["reference"], &f.reference);
  if (root["trials"]) f.trials = static_cast<int>(YamlNumber(r, root["trials"], "trials", 1, 100));
  if (hal) {
    f.hal = ParseHal(r, root["hal"], f.controller);
    if (f.hal->tau_max > f.driver_limit)
      r.Fail("hal.tau_max", Num(f.hal->tau_max) + " N m is beyond the drivers' range (drivers.torque_limit " +
                                Num(f.driver_limit) + " N m)");
  }
  return f;
}

ControllerFile ReadControllerFile(const std::string& path) {
  return ParseControllerFile(ReadYamlText(path, "controller"), path);
}

std::string ControllerFileYaml(const ControllerFile& f, const std::string& comment) {
  std::ostringstream o;
  o << "# " << comment << "\n";
  o << ControllerSpecYaml(f.controller);
  o << "drivers: {torque_limit: " << Num(f.driver_limit) << "}\n";
  if (f.hal) {
    o << "hal:\n";
    WriteHal(o, *f.hal);
    o << "trials: " << f.trials << "\n";
    return o.str();
  }
  o << "model:\n  L1: " << Num(f.model.L1) << "\n  g: " << Num(f.model.g) << "\n  exo: " << LumpedYaml(f.model.exo) << "\n";
  if (f.model.human) o << "  human: " << LumpedYaml(*f.model.human) << "\n";
  o << "  passive: " << (f.model.passive == PassiveModel::kNone ? "none" : "riener1999") << "\n";
  const ReferenceSpec& p = f.reference;
  const char* kind = p.kind == ReferenceKind::kGait         ? "gait"
                     : p.kind == ReferenceKind::kExcitation ? "excitation"
                     : p.kind == ReferenceKind::kHold       ? "hold"
                                                            : "samples";
  o << "reference: {kind: " << kind << ", stride_period: " << Num(p.stride_period) << ", moving_joint: " << p.moving_joint
    << ", excitation_seed: " << p.excitation_seed << ", ramp: " << Num(p.ramp);
  if (p.hold_hip || p.hold_knee) {
    o << ", hold: {";
    if (p.hold_hip) o << "hip: " << Num(*p.hold_hip) << (p.hold_knee ? ", " : "");
    if (p.hold_knee) o << "knee: " << Num(*p.hold_knee);
    o << "}";
  }
  if (p.kind == ReferenceKind::kSamples) {
    o << ",\n  samples: {dt: " << Num(p.sample_dt) << ", loop: " << (p.sample_loop ? "true" : "false")
      << ", cutoff: " << Num(p.sample_cutoff);
    for (const auto* a : {&p.sample_hip, &p.sample_knee}) {
      o << (a == &p.sample_hip ? ",\n    hip: [" : ",\n    knee: [");
      for (size_t i = 0; i < a->size(); ++i) o << (i ? ", " : "") << Num((*a)[i]);
      o << "]";
    }
    o << "}";
  }
  o << "}\ntrials: " << f.trials << "\n";
  return o.str();
}

}  // namespace controller
}  // namespace exotwin
