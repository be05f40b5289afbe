#include "formats/model_file.h"

#include <cmath>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/yaml_fields.h"
#include "model/effect_families.h"
#include "model/one_joint.h"
#include "model/term_expr.h"

namespace exotwin {
namespace {

LumpedParams ReadLumped(const YamlContext& c, const YAML::Node& n, const std::string& key) {
  YamlCheckKeys(c, n, key, {"J1", "J2", "X1", "X2", "Y1", "Y2", "m1", "m2"});
  LumpedParams p;
  for (const char* req : {"J1", "J2", "X1", "X2", "Y1", "Y2"})
    if (!n[req]) c.Fail(key + "." + req, "missing, expected a number");
  p.J1 = YamlNumber(c, n["J1"], key + ".J1", 0.0, 50.0, "kg m^2");
  p.J2 = YamlNumber(c, n["J2"], key + ".J2", 0.0, 50.0, "kg m^2");
  p.X1 = YamlNumber(c, n["X1"], key + ".X1", -50.0, 50.0, "kg m");
  p.X2 = YamlNumber(c, n["X2"], key + ".X2", -50.0, 50.0, "kg m");
  p.Y1 = YamlNumber(c, n["Y1"], key + ".Y1", -50.0, 50.0, "kg m");
  p.Y2 = YamlNumber(c, n["Y2"], key + ".Y2", -50.0, 50.0, "kg m");
  if (n["m1"]) {
    p.m1 = YamlNumber(c, n["m1"], key + ".m1", -1e9, 500.0, "kg");
    if (!(p.m1 > 0)) c.Fail(key + ".m1", "mass must be > 0 kg, got " + n["m1"].Scalar());
  }
  if (n["m2"]) {
    p.m2 = YamlNumber(c, n["m2"], key + ".m2", -1e9, 500.0, "kg");
    if (!(p.m2 > 0)) c.Fail(key + ".m2", "mass must be > 0 kg, got " + n["m2"].Scalar());
  }
  return p;
}

// A family's key beyond its fields (EffectFamily::keys) into e.
void ReadEffectKey(const YamlContext& c, const YAML::Node& n, const std::string& key, const EffectKey& k, Effect* e) {
  const YAML::Node v = n[k.key];
  const std::string where = key + "." + k.key;
  switch (k.kind) {
    case EffectKey::Kind::kAxis:
      e->axis = v ? v.Scalar() : "X";
      if (e->axis != "X" && e->axis != "Y") c.Fail(where, "expected X or Y");
      break;
    case EffectKey::Kind::kOptionalField:
      if (v) e->fields[k.key] = YamlNumber(c, v, where, k.lo, k.hi, "");
      break;
    case EffectKey::Kind::kWeights:
      if (!v) break;
      if (!v.IsMap()) c.Fail(where, "expected a mapping channel: N m per V");
      for (const auto& kv : v) {
        const std::string ch = kv.first.IsScalar() ? kv.first.Scalar() : "";
        const char* kIdent = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_";
        if (ch.empty() || ch.find_first_not_of(kIdent) != std::string::npos)
          c.Fail(where, "expected EMG channel names (letters, digits, '_') as keys" + YamlLine(kv.first));
        e->fields["w_" + ch] = YamlNumber(c, kv.second, where + "." + ch, -1e6, 1e6, "");
      }
      break;
    case EffectKey::Kind::kAccepted:
      break;
  }
}

// A term's expr (parsed: a parse error names the position in it) and stage (DESIGN.md "Terms beyond
// the table").
void ReadTerm(const YamlContext& c, const YAML::Node& n, const std::string& key, Effect* e) {
  const std::string what = " (" + e->name + " at the " + e->joint + ")";
  if (!n["expr"] || !n["expr"].IsScalar())
    c.Fail(key + ".expr", "missing" + what + ", expected an expression of q, qd, qdd, tau_R, q_hip, q_knee, qd_hip, "
           "qd_knee, t (DESIGN.md \"Terms beyond the table\")");
  e->expr = n["expr"].Scalar();
  try {
    TermExpr::Parse(e->expr);
  } catch (const TermExprError& x) {
    c.Fail(key + ".expr", "\"" + e->expr + "\"" + what + ": " + x.what() + " of the expression");
  }
  if (n["stage"]) {
    e->stage = n["stage"].IsScalar() ? n["stage"].Scalar() : "";
    if (e->stage != "link" && e->stage != "sensor") c.Fail(key + ".stage", "expected link or sensor" + YamlLine(n["stage"]));
  }
}

Effect ReadEffect(const YamlContext& c, const YAML::Node& n, const std::string& key) {
  if (!n.IsMap()) c.Fail(key, "expected a mapping {name, joint, value, unit, ...}" + YamlLine(n));
  if (!n["name"] || !n["name"].IsScalar()) c.Fail(key + ".name", "missing, expected an effect name");
  Effect e;
  e.name = n["name"].Scalar();
  const EffectFamily* spec = FindFamily(e.name);
  if (!spec)
    c.Fail(key + ".name", "unknown effect '" + e.name + "', expected one of: " +
                              FamilyNames());
  std::set<std::string> allowed = {"name", "joint", "value", "unit", "ci95", "explained_pct"};
  allowed.insert(spec->fields.begin(), spec->fields.end());
  for (const EffectKey& k : spec->keys) allowed.insert(k.key);
  if (spec->carries_expr) allowed.insert({"expr", "stage"});
  YamlCheckKeys(c, n, key, allowed);
  if (!n["joint"] || !n["joint"].IsScalar() ||
      (n["joint"].Scalar() != "hip" && n["joint"].Scalar() != "knee"))
    c.Fail(key + ".joint", "expected 'hip' or 'knee'");
  e.joint = n["joint"].Scalar();
  if (!n["value"]) c.Fail(key + ".value", "missing, expected a number in " + std::string(spec->unit));
  e.value = YamlNumber(c, n["value"], key + ".value", spec->lo, spec->hi, spec->unit);
  e.unit = spec->unit;
  if (n["unit"] && n["unit"].Scalar() != spec->unit)
    c.Fail(key + ".unit", "expected '" + std::string(spec->unit) + "', got '" + n["unit"].Scalar() + "'");
  for (const auto& f : spec->fields) {
    if (!n[f]) c.Fail(key + "." + f, "missing, required by " + e.name);
    e.fields[f] = YamlNumber(c, n[f], key + "." + f, -1e6, 1e6, "");
  }
  for (const EffectKey& k : spec->keys) ReadEffectKey(c, n, key, k, &e);
  if (spec->carries_expr) ReadTerm(c, n, key, &e);
  return e;
}

std::vector<Effect> ReadEffects(const YamlContext& c, const YAML::Node& root) {
  if (!root["effects"] || root["effects"].IsNull()) return {};
  return ReadEffectList(c, root["effects"], "effects");
}

OneJointLink ReadOneJointLink(const YamlContext& c, const YAML::Node& n, const std::string& key,
                              const std::set<std::string>& keys) {
  if (!n.IsMap()) c.Fail(key, "expected a mapping {I, mgl" + std::string(keys.count("R") ? ", R, C}" : "}"));
  YamlCheckKeys(c, n, key, keys);
  OneJointLink l;
  for (const char* req : {"I", "mgl"})
    if (!n[req]) c.Fail(key + "." + req, "missing, expected a number");
  l.I = YamlNumber(c, n["I"], key + ".I", 0.0, 50.0, "kg m^2");
  l.mgl = YamlNumber(c, n["mgl"], key + ".mgl", -500.0, 500.0, "N m");
  return l;
}

// A one-joint model file (DESIGN.md "One-joint devices"): joint, device {I, mgl, R, C}, human {I, mgl},
// g, effects (at the knee).
LegParams ParseOneJointYaml(const YamlContext& c, const YAML::Node& root) {
  YamlCheckKeys(c, root, "", {"joint", "g", "device", "human", "effects", "identification", "name"});
  const std::string joint = root["joint"].IsScalar() ? root["joint"].Scalar() : "";
  if (joint != "knee")
    c.Fail("joint", "'" + joint + "', expected 'knee' (a one-joint device's joint; its columns are q_knee, tau_knee)");
  double g = 9.81;
  if (root["g"]) g = YamlNumber(c, root["g"], "g", 0.0, 20.0, "m/s^2");
  if (!root["device"]) c.Fail("device", "missing, expected {I, mgl, R, C} of the device's link");
  OneJointModel m;
  const YAML::Node dev = root["device"];
  m.device = ReadOneJointLink(c, dev, "device", {"I", "mgl", "R", "C"});
  if (dev["R"]) m.R = YamlNumber(c, dev["R"], "device.R", 0.0, 100.0, "N m s/rad");
  if (dev["C"]) m.C = YamlNumber(c, dev["C"], "device.C", 0.0, 100.0, "N m");
  if (root["human"] && !root["human"].IsNull()) m.human = ReadOneJointLink(c, root["human"], "human", {"I", "mgl"});
  if (!(m.device.I + (m.human ? m.human->I : 0.0) > 0))
    c.Fail("device.I", "the joint's total inertia is 0, expected > 0 kg m^2");
  const std::vector<Effect> effects = ReadEffects(c, root);
  for (size_t i = 0; i < effects.size(); ++i)
    if (effects[i].joint != "knee")
      c.Fail("effects[" + std::to_string(i) + "].joint",
             "'" + effects[i].joint + "' in a one-joint model file, expected 'knee'");
  return EmbedOneJointModel(m, g, effects);
}

}  // namespace

LegParams ParseModelYaml(const std::string& text, const std::string& source) {
  YamlContext c{source};
  const YAML::Node root = ParseYaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty model file, expected L1 and exo:");
  if (!root.IsMap()) throw InputError(source + ": expected a YAML mapping at the top level");
  if (root["joint"]) return ParseOneJointYaml(c, root);
  YamlCheckKeys(c, root, "", {"L1", "g", "exo", "human", "passive", "effects", "identification", "name"});
  LegParams p;
  if (!root["L1"]) c.Fail("L1", "missing, expected the thigh length in m");
  p.L1 = YamlNumber(c, root["L1"], "L1", 0.1, 1.0, "m");
  if (root["g"]) p.g = YamlNumber(c, root["g"], "g", 0.0, 20.0, "m/s^2");
  if (!root["exo"]) c.Fail("exo", "missing, expected {J1, J2, X1, X2, Y1, Y2}");
  p.exo = ReadLumped(c, root["exo"], "exo");
  if (root["human"] && !root["human"].IsNull()) p.human = ReadLumped(c, root["human"], "human");
  if (root["passive"]) {
    const std::string s = root["passive"].IsScalar() ? root["passive"].Scalar() : "";
    if (s == "none") p.passive = PassiveModel::kNone;
    else if (s == "riener1999") p.passive = PassiveModel::kRiener1999;
    else c.Fail("passive", "expected 'none' or 'riener1999', got '" + s + "'");
    if (p.passive != PassiveModel::kNone && !p.human)
      c.Fail("passive", "acts on the human only: expected 'none' without a human: block");
  }
  p.effects = ReadEffects(c, root);
  return p;
}

void CheckRecordFitsModel(const LegParams& params, const std::string& params_path, const MeasuredData& data) {
  if (params.one_joint && !data.one_joint)
    throw InputError(data.source + ": a record with hip columns (q_hip, tau_hip, ...) given the one-joint model file " +
                     params_path + ", expected a one-joint record (t, q_knee, tau_knee, optional cmd_knee, emg_*; "
                     "no hip column) or a two-joint model file");
  if (!params.one_joint && data.one_joint)
    throw InputError(data.source + ": a one-joint record (q_knee, tau_knee, no hip column) given the two-joint model "
                     "file " + params_path + ", expected t, q_hip, q_knee, tau_hip, tau_knee, or a one-joint model "
                     "file (joint: knee)");
}

std::vector<Effect> ReadEffectList(const YamlContext& c, const YAML::Node& n, const std::string& key) {
  if (!n.IsSequence()) c.Fail(key, "expected a list" + YamlLine(n));
  std::vector<Effect> out;
  int i = 0;
  for (const auto& e : n) out.push_back(ReadEffect(c, e, key + "[" + std::to_string(i++) + "]"));
  return out;
}

LegParams ReadModelFile(const std::string& path) {
  return ParseModelYaml(ReadYamlText(path, "model"), path);
}

namespace {

std::string Num(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

std::string Block(const LumpedParams& p) {
  std::string s = "{J1: " + Num(p.J1) + ", J2: " + Num(p.J2) + ", X1: " + Num(p.X1) +
                  ", X2: " + Num(p.X2) + ", Y1: " + Num(p.Y1) + ", Y2: " + Num(p.Y2);
  if (p.m1 > 0) s += ", m1: " + Num(p.m1);
  if (p.m2 > 0) s += ", m2: " + Num(p.m2);
  return s + "}";
}

void WriteEffects(std::ostringstream& os, const std::vector<Effect>& effects) {
  if (effects.empty()) {
    os << "effects: []\n";
  } else {
    os << "effects:\n";
    for (const Effect& e : effects) {
      os << "  - {name: " << e.name << ", joint: " << e.joint << ", value: " << Num(e.value)
         << ", unit: \"" << e.unit << "\"";
      if (!e.axis.empty()) os << ", axis: " << e.axis;
      if (!e.expr.empty()) os << ", expr: \"" << e.expr << "\"";
      if (!e.stage.empty()) os << ", stage: " << e.stage;
      std::string weights;
      for (const auto& f : e.fields) {
        if (f.first.rfind("w_", 0) == 0) weights += (weights.empty() ? "" : ", ") + f.first.substr(2) + ": " + Num(f.second);
        else os << ", " << f.first << ": " << Num(f.second);
      }
      if (!weights.empty()) os << ", weights: {" << weights << "}";
      os << "}\n";
    }
  }
}

}  // namespace

std::string ModelToYaml(const LegParams& params, const std::string& header,
                        const std::string& extra_yaml) {
  std::ostringstream os;
  if (!header.empty()) {
    std::stringstream hs(header);
    std::string line;
    while (std::getline(hs, line)) os << "# " << line << "\n";
  }
  if (params.one_joint) {
    const OneJointModel& m = *params.one_joint;
    os << "joint: knee                    # a one-joint device (HKS05 eq. 4), th = 0 hanging, + extension\n";
    if (params.g != 9.81) os << "g: " << Num(params.g) << "\n";
    os << "device: {I: " << Num(m.device.I) << ", mgl: " << Num(m.device.mgl) << ", R: " << Num(m.R)
       << ", C: " << Num(m.C) << "}\n";
    if (m.human) os << "human: {I: " << Num(m.human->I) << ", mgl: " << Num(m.human->mgl) << "}\n";
    WriteEffects(os, std::vector<Effect>(params.effects.begin() + static_cast<long>(m.device_effects),
                                         params.effects.end()));
    os << extra_yaml;
    return os.str();
  }
  os << "L1: " << Num(params.L1) << "                      # thigh length, m\n";
  if (params.g != 9.81) os << "g: " << Num(params.g) << "\n";
  os << "exo:   " << Block(params.exo) << "\n";
  if (params.human) os << "human: " << Block(*params.human) << "\n";
  os << "passive: " << PassiveModelName(params.passive) << "\n";
  WriteEffects(os, params.effects);
  os << extra_yaml;
  return os.str();
}

}  // namespace exotwin
