// The model file's effect keys beyond name, joint, value, unit and a family's fields: each family's
// key list (EffectFamily::keys) says which it takes and how they are read; the writer gives them back.
// A term's expr and stage (DESIGN.md "Terms beyond the table") likewise, and bad input naming the file,
// the effect and the position in expr.
#include <gtest/gtest.h>

#include <string>

#include "../expect_input_error.h"
#include "formats/model_file.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

using testing::ExpectInputError;

const char* kRigid = "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n";

LegParams WithEffects(const std::string& list) {
  return ParseModelYaml(std::string(kRigid) + "effects: " + list + "\n", "m.yaml");
}
// The same with the effects as a block list ("  - {...}\n" lines).
LegParams Parse(const std::string& effects) { return WithEffects("\n" + effects); }

TEST(ModelFile, EachFamilysKeysAreReadByKind) {
  // kAxis: X by default, Y where given.
  const LegParams p = WithEffects(
      "[{name: gravity_error, joint: hip, value: 0.1}, {name: gravity_error, joint: knee, value: -0.2, axis: Y}, "
      "{name: passive_moment, joint: knee, value: 0.5, cv: 0.25}, {name: passive_moment, joint: hip, value: 0.5}, "
      "{name: muscle_activity, joint: knee, value: 1, weights: {VM: 2.5, ST: -1.5}, channels: [VM, ST]}]");
  ASSERT_EQ(p.effects.size(), 5u);
  EXPECT_EQ(p.effects[0].axis, "X");
  EXPECT_EQ(p.effects[1].axis, "Y");
  EXPECT_EQ(p.effects[1].value, -0.2);
  // kOptionalField: a number into fields where given, nothing where not.
  EXPECT_EQ(p.effects[2].fields.at("cv"), 0.25);
  EXPECT_EQ(p.effects[3].fields.count("cv"), 0u);
  // kWeights: one field per channel; kAccepted (channels): read and ignored.
  EXPECT_EQ(p.effects[4].fields.size(), 2u);
  EXPECT_EQ(p.effects[4].fields.at("w_VM"), 2.5);
  EXPECT_EQ(p.effects[4].fields.at("w_ST"), -1.5);
  EXPECT_TRUE(p.effects[4].axis.empty());
  // The writer gives every key back.
  const LegParams back = ParseModelYaml(ModelToYaml(p), "back.yaml");
  ASSERT_EQ(back.effects.size(), p.effects.size());
  for (size_t i = 0; i < p.effects.size(); ++i) {
    EXPECT_EQ(back.effects[i].name, p.effects[i].name) << i;
    EXPECT_EQ(back.effects[i].axis, p.effects[i].axis) << i;
    EXPECT_EQ(back.effects[i].value, p.effects[i].value) << i;
    EXPECT_EQ(back.effects[i].fields, p.effects[i].fields) << i;
  }
}

TEST(ModelFile, AKeyOutsideItsFamilysListOrItsKindIsRefused) {
  // Another family's key.
  ExpectInputError([] { WithEffects("[{name: coulomb_friction, joint: knee, value: 1, axis: Y}]"); },
                   {"m.yaml", "effects[0]", "axis"});
  ExpectInputError([] { WithEffects("[{name: gravity_error, joint: knee, value: 0.1, cv: 0.2}]"); },
                   {"m.yaml", "effects[0]", "cv"});
  // Its kind's values.
  ExpectInputError([] { WithEffects("[{name: gravity_error, joint: knee, value: 0.1, axis: Z}]"); },
                   {"effects[0].axis", "expected X or Y"});
  ExpectInputError([] { WithEffects("[{name: passive_moment, joint: knee, value: 0.1, cv: 3}]"); },
                   {"effects[0].cv"});
  ExpectInputError([] { WithEffects("[{name: muscle_activity, joint: knee, value: 1, weights: [1, 2]}]"); },
                   {"effects[0].weights", "expected a mapping"});
  ExpectInputError([] { WithEffects("[{name: muscle_activity, joint: knee, value: 1, weights: {a-b: 1}}]"); },
                   {"effects[0].weights", "EMG channel names"});
}

// A family added with its own key (a device's effect): the model file reads and writes it without a
// change to the reader.
struct SpreadFamily {  // registered for one test (the registry is the process's)
  SpreadFamily() {
    EffectFamily f{"toy_spread", "N m", 0.0, 10.0, {}, EffectStage::kLink, PlantCarrier::kNotCarried, "", "a toy"};
    f.keys = {{"spread", EffectKey::Kind::kOptionalField, 0.0, 1.0}};
    AddEffectFamily(f);
  }
  ~SpreadFamily() { RemoveAddedEffectFamily("toy_spread"); }
};

TEST(ModelFile, AnAddedFamilysKeyIsReadAndWritten) {
  const SpreadFamily toy;
  const LegParams p = WithEffects("[{name: toy_spread, joint: knee, value: 2, spread: 0.75}]");
  ASSERT_EQ(p.effects.size(), 1u);
  EXPECT_EQ(p.effects[0].fields.at("spread"), 0.75);
  const LegParams back = ParseModelYaml(ModelToYaml(p), "back.yaml");
  ASSERT_EQ(back.effects.size(), 1u);
  EXPECT_EQ(back.effects[0].fields.at("spread"), 0.75);
  testing::ExpectInputError([] { WithEffects("[{name: toy_spread, joint: knee, value: 2, spread: 1.5}]"); },
                            {"effects[0].spread"});
}

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
