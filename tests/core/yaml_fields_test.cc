// The YAML field validators: values accepted in range, and every failure an InputError naming the
// source, the key path, the line and what was expected.
#include "core/yaml_fields.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace exotwin {
namespace {

const YamlContext kC{"f.yaml"};

template <class F>
std::string MessageOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(YamlFields, NumbersInRangeAndTheirErrors) {
  const YAML::Node n = ParseYaml("a: 1.5\nb: x\nc: .nan\nd: 1e3\ne: [1, 2]\nf: [1]\n", "f.yaml");
  EXPECT_EQ(YamlNumber(kC, n["a"], "a", 0, 2, "m"), 1.5);
  EXPECT_EQ(MessageOf([&] { YamlNumber(kC, n["b"], "b", 0, 2); }), "f.yaml: b: 'x' is not a number (line 2)");
  EXPECT_EQ(MessageOf([&] { YamlNumber(kC, n["c"], "c", 0, 2, "s"); }),
            "f.yaml: c: expected a finite number, got .nan (expected 0 .. 2 s) (line 3)");
  EXPECT_EQ(MessageOf([&] { YamlNumber(kC, n["d"], "d", 0, 2); }),
            "f.yaml: d: value 1e3 out of range, expected 0 .. 2 (line 4)");
  EXPECT_EQ(MessageOf([&] { YamlNumber(kC, n["zz"], "zz", 0, 2); }), "f.yaml: zz: expected a number");
  double pair[2];
  YamlNumberPair(kC, n["e"], "e", pair, 0, 5);
  EXPECT_EQ(pair[0], 1.0);
  EXPECT_EQ(pair[1], 2.0);
  EXPECT_EQ(MessageOf([&] { YamlNumberPair(kC, n["f"], "f", pair, 0, 5); }), "f.yaml: f: expected [hip, knee] (line 6)");
  EXPECT_EQ(MessageOf([&] { YamlNumberPair(kC, n["e"], "e", pair, 0, 1.5); }),
            "f.yaml: e[1]: value 2 out of range, expected 0 .. 1.5 (line 5)");
}

TEST(YamlFields, StringsBoolsAndKeys) {
  const YAML::Node n = ParseYaml("mode: on\nflag: yes\nbad: maybe\n", "f.yaml");
  EXPECT_EQ(YamlString(kC, n["mode"], "mode", {"on", "off"}), "on");
  EXPECT_EQ(MessageOf([&] { YamlString(kC, n["bad"], "bad", {"on", "off"}); }),
            "f.yaml: bad: 'maybe' is not one of: off, on (line 3)");
  EXPECT_TRUE(YamlBool(kC, n["flag"], "flag"));
  EXPECT_EQ(MessageOf([&] { YamlBool(kC, n["bad"], "bad"); }), "f.yaml: bad: 'maybe' is not true/false (line 3)");
  YamlCheckKeys(kC, n, "", {"mode", "flag", "bad"});
  EXPECT_EQ(MessageOf([&] { YamlCheckKeys(kC, n, "", {"mode", "flag"}); }),
            "f.yaml: bad: unknown key (line 3), expected one of: flag, mode");
  const YAML::Node dup = ParseYaml("top: {a: 1, a: 2}\n", "f.yaml");
  EXPECT_EQ(MessageOf([&] { YamlCheckKeys(kC, dup["top"], "top", {"a"}); }), "f.yaml: top.a: duplicated key (line 1)");
  EXPECT_EQ(MessageOf([] { ParseYaml("a: [1\n", "f.yaml"); }).rfind("f.yaml: line ", 0), 0u);
}

}  // namespace
}  // namespace exotwin
