// The model file's effect keys beyond name, joint, value, unit and a family's fields: each family's
// key list (EffectFamily::keys) says which it takes and how they are read; the writer gives them back.
#include <gtest/gtest.h>

#include <string>

#include "../expect_input_error.h"
#include "formats/model_file.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

const char* kRigid = "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n";

LegParams WithEffects(const std::string& list) {
  return ParseModelYaml(std::string(kRigid) + "effects: " + list + "\n", "m.yaml");
}

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
  using testing::ExpectInputError;
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

}  // namespace
}  // namespace exotwin
