// The model file's terms (formats/model_file.h, DESIGN.md "Terms beyond the table"): expr and stage
// read and written back, and bad input naming the file, the effect and the position in expr.
#include "formats/model_file.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/expect_input_error.h"

namespace exotwin {
namespace {

using testing::ExpectInputError;

const std::string kHead =
    "L1: 0.41\n"
    "exo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n";

LegParams Parse(const std::string& effects) { return ParseModelYaml(kHead + "effects:\n" + effects, "m.yaml"); }

TEST(ModelFileTerms, ReadAndWrittenBack) {
  const LegParams p = Parse(
      "  - {name: term, joint: knee, value: 0.061, unit: \"N m\", expr: \"abs(tau_R) * sgn(qd)\"}\n"
      "  - {name: term, joint: hip, value: 1.9, expr: \"exp(-t / 14.2) * sgn(qd)\", stage: link}\n"
      "  - {name: term, joint: hip, value: -0.0016, unit: \"N m\", expr: \"tau_R * abs(tau_R)\", stage: sensor}\n"
      "  - {name: coulomb_friction, joint: knee, value: 0.5}\n");
  ASSERT_EQ(p.effects.size(), 4u);
  EXPECT_EQ(p.effects[0].expr, "abs(tau_R) * sgn(qd)");
  EXPECT_EQ(p.effects[0].stage, "");
  EXPECT_EQ(p.effects[0].value, 0.061);
  EXPECT_EQ(p.effects[0].unit, "N m");
  EXPECT_EQ(p.effects[1].stage, "link");
  EXPECT_EQ(p.effects[2].stage, "sensor");
  EXPECT_EQ(p.effects[2].value, -0.0016);
  EXPECT_EQ(p.effects[3].expr, "");
  const LegParams q = ParseModelYaml(ModelToYaml(p), "extended.yaml");
  ASSERT_EQ(q.effects.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(q.effects[i].name, p.effects[i].name) << i;
    EXPECT_EQ(q.effects[i].joint, p.effects[i].joint) << i;
    EXPECT_EQ(q.effects[i].value, p.effects[i].value) << i;
    EXPECT_EQ(q.effects[i].expr, p.effects[i].expr) << i;
    EXPECT_EQ(q.effects[i].stage, p.effects[i].stage) << i;
  }
  EXPECT_EQ(ModelToYaml(q), ModelToYaml(p));
}

TEST(ModelFileTerms, BadInputNamesTheFileTheEffectAndThePosition) {
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1, expr: \"abs(tau_R) * sgn(qx)\"}\n"); },
                   {"m.yaml", "effects[0].expr", "term at the knee", "unknown signal 'qx'", "position 17"});
  ExpectInputError(
      [] {
        Parse("  - {name: coulomb_friction, joint: knee, value: 1}\n"
              "  - {name: term, joint: hip, value: 1, expr: \"sin(q\"}\n");
      },
      {"m.yaml", "effects[1].expr", "term at the hip", "expected ')'", "position 5"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1, expr: \"q^qd\"}\n"); },
                   {"effects[0].expr", "exponent", "position 2"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1, expr: \"\"}\n"); },
                   {"effects[0].expr", "position 0"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1, expr: \"2 * 1e999\"}\n"); },
                   {"effects[0].expr", "not a finite", "position 4"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1}\n"); }, {"m.yaml", "effects[0].expr", "missing"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: .nan, expr: \"q\"}\n"); },
                   {"m.yaml", "effects[0].value"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: .inf, expr: \"q\"}\n"); },
                   {"m.yaml", "effects[0].value"});
  ExpectInputError([] { Parse("  - {name: term, joint: knee, value: 1, expr: \"q\", stage: motor}\n"); },
                   {"m.yaml", "effects[0].stage", "link or sensor"});
  // expr and stage belong to a term only.
  ExpectInputError([] { Parse("  - {name: coulomb_friction, joint: knee, value: 1, expr: \"q\"}\n"); },
                   {"m.yaml", "effects[0]", "expr"});
  ExpectInputError([] { Parse("  - {name: sensor_offset, joint: knee, value: 1, stage: sensor}\n"); },
                   {"m.yaml", "effects[0]", "stage"});
}

}  // namespace
}  // namespace exotwin
