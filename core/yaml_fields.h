// Strict reading of exotwin's YAML input files (MODEL.yaml, column maps, scenarios, controller
// files): every failure is an InputError naming the file, the key path (e.g. "exo.J1",
// "columns.q_hip.scale", "controller.kp[0]"), the YAML line where known, and what was expected.
#pragma once
#include <yaml-cpp/yaml.h>

#include <functional>
#include <set>
#include <string>

namespace exotwin {

// The file being read; Fail throws InputError("<source>: <key>: <what>").
struct YamlContext {
  std::string source;
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;
};

// " (line N)" for a node with a position (1-based), else "" (also for a missing key).
std::string YamlLine(const YAML::Node& n);

// A finite number in [lo, hi] (`unit`, if any, is named in the message). Fails on a missing or
// non-scalar node ("expected a number"), text that is not a number ("'x' is not a number"), inf/NaN
// ("expected a finite number, got x (expected lo .. hi unit)") or a value out of range ("value x out
// of range, expected lo .. hi unit"); x is the text as written.
double YamlNumber(const YamlContext& c, const YAML::Node& n, const std::string& key, double lo, double hi,
                  const std::string& unit = "");

// Two numbers [hip, knee], each as YamlNumber (keys "<key>[0]", "<key>[1]"), into out[0], out[1].
void YamlNumberPair(const YamlContext& c, const YAML::Node& n, const std::string& key, double out[2], double lo,
                    double hi);

// A string scalar; with a non-empty `allowed`, one of those ("'x' is not one of: a, b").
std::string YamlString(const YamlContext& c, const YAML::Node& n, const std::string& key,
                       const std::set<std::string>& allowed = {});

// true or false (YAML's boolean spellings).
bool YamlBool(const YamlContext& c, const YAML::Node& n, const std::string& key);

// Checks that `map` is a mapping with plain, unique keys, each accepted by `allowed` ("" key: the
// top level). `expected` lists the accepted keys for the message.
void YamlCheckKeys(const YamlContext& c, const YAML::Node& map, const std::string& key,
                   const std::function<bool(const std::string&)>& allowed, const std::string& expected);
// The same with a fixed set of keys.
void YamlCheckKeys(const YamlContext& c, const YAML::Node& map, const std::string& key,
                   const std::set<std::string>& allowed);

// The text of a YAML file (ReadTextFile): "<path>: cannot open <what> file (<reason>)", or for a NUL
// byte "<path>: binary data (NUL byte), expected a YAML text file".
std::string ReadYamlText(const std::string& path, const std::string& what);

// Parses YAML text; malformed YAML throws "<source>: line N: malformed YAML: <reason>".
YAML::Node ParseYaml(const std::string& text, const std::string& source);

}  // namespace exotwin
