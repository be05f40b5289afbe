#include "analysis/yaml_fields.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "model/input_error.h"

namespace exotwin {

void YamlContext::Fail(const std::string& key, const std::string& what) const {
  throw InputError(source + ": " + key + ": " + what);
}

std::string YamlLine(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.line >= 0 ? " (line " + std::to_string(m.line + 1) + ")" : "";
}

double YamlNumber(const YamlContext& c, const YAML::Node& n, const std::string& key, double lo, double hi,
                  const std::string& unit) {
  if (!n || !n.IsScalar()) c.Fail(key, "expected a number" + YamlLine(n));
  double v;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    c.Fail(key, "'" + n.Scalar() + "' is not a number" + YamlLine(n));
  }
  if (!std::isfinite(v)) c.Fail(key, "expected a finite number, got " + n.Scalar() + YamlLine(n));
  if (v < lo || v > hi) {
    std::ostringstream os;
    os << "value " << v << " out of range, expected " << lo << " .. " << hi << (unit.empty() ? "" : " ") << unit
       << YamlLine(n);
    c.Fail(key, os.str());
  }
  return v;
}

void YamlCheckKeys(const YamlContext& c, const YAML::Node& map, const std::string& key,
                   const std::function<bool(const std::string&)>& allowed, const std::string& expected) {
  if (!map.IsMap()) c.Fail(key, "expected a mapping" + YamlLine(map));
  std::set<std::string> seen;
  for (const auto& kv : map) {
    if (!kv.first.IsScalar())
      c.Fail(key.empty() ? "(top level)" : key, "expected plain keys, found a non-scalar key" + YamlLine(kv.first));
    const std::string k = kv.first.Scalar();
    const std::string path = key.empty() ? k : key + "." + k;
    if (!seen.insert(k).second) c.Fail(path, "duplicated key" + YamlLine(kv.first));
    if (!allowed(k)) c.Fail(path, "unknown key" + YamlLine(kv.first) + ", expected one of: " + expected);
  }
}

void YamlCheckKeys(const YamlContext& c, const YAML::Node& map, const std::string& key,
                   const std::set<std::string>& allowed) {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  YamlCheckKeys(c, map, key, [&](const std::string& k) { return allowed.count(k) > 0; }, list);
}

std::string ReadYamlText(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open " + what + " file");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  if (text.find('\0') != std::string::npos)
    throw InputError(path + ": binary data (NUL byte), expected a YAML text file");
  return text;
}

YAML::Node ParseYaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": line " + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
}

}  // namespace exotwin
