#include "core/yaml_fields.h"

#include <yaml-cpp/eventhandler.h>

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/file_text.h"

namespace exotwin {

namespace {

std::string List(const std::set<std::string>& items) {
  std::string list;
  for (const auto& a : items) list += (list.empty() ? "" : ", ") + a;
  return list;
}

// Checks every scalar (keys included) the YAML text gives: a double-quoted string's escapes
// ("\xC1", "\uD800", "\0", "\e") can make invalid text out of valid text.
class ScalarCheck : public YAML::EventHandler {
 public:
  explicit ScalarCheck(const std::string& source) : source_(source) {}
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t, const std::string& value) override {
    if (const auto f = FindTextFault(value))
      throw InputError(source_ + ": line " + std::to_string(mark.line + 1) + ": a string holds " + f->Where() +
                       " of its value, expected UTF-8 text without control characters (check its escape sequences)");
  }
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

 private:
  const std::string& source_;
};

}  // namespace

void YamlContext::Fail(const std::string& key, const std::string& what) const {
  throw InputError(source + ": " + key + ": " + what);
}

std::string YamlLine(const YAML::Node& n) {
  if (!n.IsDefined()) return "";  // a missing key: no position
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
  std::ostringstream range;
  range << "expected " << lo << " .. " << hi << (unit.empty() ? "" : " ") << unit;
  if (!std::isfinite(v)) c.Fail(key, "expected a finite number, got " + n.Scalar() + " (" + range.str() + ")" + YamlLine(n));
  if (v < lo || v > hi) c.Fail(key, "value " + n.Scalar() + " out of range, " + range.str() + YamlLine(n));
  return v;
}

void YamlNumberPair(const YamlContext& c, const YAML::Node& n, const std::string& key, double out[2], double lo,
                    double hi) {
  if (!n.IsSequence() || n.size() != 2) c.Fail(key, "expected [hip, knee]" + YamlLine(n));
  out[0] = YamlNumber(c, n[0], key + "[0]", lo, hi);
  out[1] = YamlNumber(c, n[1], key + "[1]", lo, hi);
}

std::string YamlString(const YamlContext& c, const YAML::Node& n, const std::string& key,
                       const std::set<std::string>& allowed) {
  if (!n || !n.IsScalar()) c.Fail(key, "expected a string" + YamlLine(n));
  const std::string s = n.Scalar();
  if (!allowed.empty() && !allowed.count(s)) c.Fail(key, "'" + s + "' is not one of: " + List(allowed) + YamlLine(n));
  return s;
}

bool YamlBool(const YamlContext& c, const YAML::Node& n, const std::string& key) {
  if (!n || !n.IsScalar()) c.Fail(key, "expected true or false" + YamlLine(n));
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    c.Fail(key, "'" + n.Scalar() + "' is not true/false" + YamlLine(n));
  }
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
  YamlCheckKeys(c, map, key, [&](const std::string& k) { return allowed.count(k) > 0; }, List(allowed));
}

std::string ReadYamlText(const std::string& path, const std::string& what) {
  return ReadTextFile(path, what, "a YAML text file");
}

YAML::Node ParseYaml(const std::string& text, const std::string& source) {
  CheckText(text, source, "a YAML text");
  try {
    if (text.find('\\') != std::string::npos) {  // escapes only exist after a backslash
      std::istringstream in(text);
      YAML::Parser parser(in);
      ScalarCheck check(source);
      // The first document only, as YAML::Load: yaml-cpp 0.7 can loop for ever looking for a next
      // document after a malformed one (found by fuzz_model_yaml, fuzz/corpus/*/crash_second_document_*).
      parser.HandleNextDocument(check);
    }
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": line " + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
}

}  // namespace exotwin
