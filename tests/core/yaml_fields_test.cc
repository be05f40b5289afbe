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

// Text that is not valid UTF-8 (or holds a control character) is refused before it is parsed, and
// so is a string whose escapes make such text out of valid text: every string of a parsed node can
// be written to JSON as it is.
TEST(YamlFields, InvalidTextAndEscapesAreRefused) {
  EXPECT_EQ(MessageOf([] { ParseYaml("name: ok\nchecks: [{name: \"a\xc1\"}]\n", "s.yaml"); }),
            "s.yaml: invalid UTF-8 (byte 0xC1) at line 2, byte 19, expected a YAML text");
  // yaml-cpp writes the escape \N (U+0085) as the single byte 0x85: valid YAML text, invalid UTF-8 string.
  EXPECT_EQ(MessageOf([] { ParseYaml("a: 1\nname: \"x\\xC1\\N\"\n", "s.yaml"); }),
            "s.yaml: line 2: a string holds invalid UTF-8 (byte 0x85) at line 1, byte 4 of its "
            "value, expected UTF-8 text without control characters (check its escape sequences)");
  EXPECT_EQ(MessageOf([] { ParseYaml("{\"k\\e\": 1}\n", "s.yaml"); }).rfind("s.yaml: line 1: a string holds control character 0x1B", 0), 0u);
  EXPECT_EQ(MessageOf([] { ParseYaml("a: \"\\x85\"\n", "s.yaml"); }).rfind("s.yaml: line 1: a string holds control character U+0085 (C1)", 0), 0u);
  EXPECT_EQ(MessageOf([] { ParseYaml("a: \"\\0\"\n", "s.yaml"); }).rfind("s.yaml: line 1: a string holds binary data (NUL byte)", 0), 0u);
  // Valid escapes and text pass.
  const YAML::Node n = ParseYaml("a: \"caf\\xe9 \\u20ac \\t\"\nb: 'x\\y'\nc: |\n  two\n  lines\n", "s.yaml");
  EXPECT_EQ(n["a"].Scalar(), "caf\xc3\xa9 \xe2\x82\xac \t");
  EXPECT_EQ(n["b"].Scalar(), "x\\y");
}

}  // namespace
}  // namespace exotwin
