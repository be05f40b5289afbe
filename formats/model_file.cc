#include "formats/model_file.h"

#include <cmath>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/yaml_fields.h"

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

struct EffectSpec {
  const char* name;
  const char* unit;
  double lo, hi;
  std::set<std::string> fields;  // extra numeric fields (required)
};

const std::vector<EffectSpec>& EffectSpecs() {
  static const std::vector<EffectSpec> kSpecs = {
      {"coulomb_friction", "N m", 0.0, 100.0, {}},
      {"viscous_friction", "N m s/rad", -100.0, 100.0, {}},
      {"inertia_error", "kg m^2", -10.0, 10.0, {}},
      {"gravity_error", "kg m", -20.0, 20.0, {}},
      {"joint_stiffness", "N m/rad", -1000.0, 1000.0, {"q0"}},
      {"backlash", "rad", 0.0, 0.5, {}},
      {"series_compliance", "N m/rad", 1.0, 1e6, {}},
      {"torque_ripple", "N m", 0.0, 100.0, {"cycles_per_rad", "phase"}},
      {"sensor_offset", "N m", -100.0, 100.0, {}},
      {"sensor_gain", "relative", -0.9, 10.0, {}},
      {"sensor_delay", "s", 0.0, 1.0, {}},
      {"muscle_activity", "-", -1e6, 1e6, {}},
  };
  return kSpecs;
}

Effect ReadEffect(const YamlContext& c, const YAML::Node& n, const std::string& key) {
  if (!n.IsMap()) c.Fail(key, "expected a mapping {name, joint, value, unit, ...}" + YamlLine(n));
  if (!n["name"] || !n["name"].IsScalar()) c.Fail(key + ".name", "missing, expected an effect name");
  Effect e;
  e.name = n["name"].Scalar();
  const EffectSpec* spec = nullptr;
  for (const auto& s : EffectSpecs())
    if (e.name == s.name) spec = &s;
  if (!spec) {
    std::string list;
    for (const auto& s : EffectSpecs()) list += (list.empty() ? "" : ", ") + std::string(s.name);
    c.Fail(key + ".name", "unknown effect '" + e.name + "', expected one of: " + list);
  }
  std::set<std::string> allowed = {"name", "joint", "value", "unit", "ci95", "explained_pct"};
  allowed.insert(spec->fields.begin(), spec->fields.end());
  if (e.name == "gravity_error") allowed.insert("axis");
  if (e.name == "muscle_activity") allowed.insert({"weights", "channels"});
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
  if (e.name == "gravity_error") {
    e.axis = n["axis"] ? n["axis"].Scalar() : "X";
    if (e.axis != "X" && e.axis != "Y") c.Fail(key + ".axis", "expected X or Y");
  }
  if (e.name == "muscle_activity" && n["weights"]) {
    if (!n["weights"].IsMap()) c.Fail(key + ".weights", "expected a mapping channel: N m per V");
    for (const auto& kv : n["weights"]) {
      const std::string ch = kv.first.IsScalar() ? kv.first.Scalar() : "";
      const char* kIdent = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_";
      if (ch.empty() || ch.find_first_not_of(kIdent) != std::string::npos)
        c.Fail(key + ".weights", "expected EMG channel names (letters, digits, '_') as keys" + YamlLine(kv.first));
      e.fields["w_" + ch] = YamlNumber(c, kv.second, key + ".weights." + ch, -1e6, 1e6, "");
    }
  }
  return e;
}

}  // namespace

LegParams ParseModelYaml(const std::string& text, const std::string& source) {
  YamlContext c{source};
  const YAML::Node root = ParseYaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty model file, expected L1 and exo:");
  if (!root.IsMap()) throw InputError(source + ": expected a YAML mapping at the top level");
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
  if (root["effects"] && !root["effects"].IsNull()) p.effects = ReadEffectList(c, root["effects"], "effects");
  return p;
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

}  // namespace

std::string ModelToYaml(const LegParams& params, const std::string& header,
                        const std::string& extra_yaml) {
  std::ostringstream os;
  if (!header.empty()) {
    std::stringstream hs(header);
    std::string line;
    while (std::getline(hs, line)) os << "# " << line << "\n";
  }
  os << "L1: " << Num(params.L1) << "                      # thigh length, m\n";
  if (params.g != 9.81) os << "g: " << Num(params.g) << "\n";
  os << "exo:   " << Block(params.exo) << "\n";
  if (params.human) os << "human: " << Block(*params.human) << "\n";
  os << "passive: " << PassiveModelName(params.passive) << "\n";
  if (params.effects.empty()) {
    os << "effects: []\n";
  } else {
    os << "effects:\n";
    for (const Effect& e : params.effects) {
      os << "  - {name: " << e.name << ", joint: " << e.joint << ", value: " << Num(e.value)
         << ", unit: \"" << e.unit << "\"";
      if (!e.axis.empty()) os << ", axis: " << e.axis;
      std::string weights;
      for (const auto& f : e.fields) {
        if (f.first.rfind("w_", 0) == 0) weights += (weights.empty() ? "" : ", ") + f.first.substr(2) + ": " + Num(f.second);
        else os << ", " << f.first << ": " << Num(f.second);
      }
      if (!weights.empty()) os << ", weights: {" << weights << "}";
      os << "}\n";
    }
  }
  os << extra_yaml;
  return os.str();
}

}  // namespace exotwin
