// Scenarios on an extended plant (DESIGN.md: plant: {effects: [...]} / {effects_from: FILE}): the
// block's bad input, and the target: the shipped gait scenario on a plant carrying a knee
// Coulomb friction of 2 N m, diagnosed with the rigid subject model, names that friction and nothing
// else (the known ground truth).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/replay.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "runner/runner.h"
#include "runner/scenario.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

const std::string kSrc = EXOTWIN_SOURCE_DIR;

std::string GaitWith(const std::string& plant_block) {
  std::ifstream in(kSrc + "/scenarios/gait_2kmh.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text + plant_block + "\n";
}

void ExpectScenarioError(const std::string& text, const std::string& must_contain) {
  try {
    ParseScenarioYaml(text, "dir/s.yaml");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(must_contain), std::string::npos) << e.what();
  }
}

// A 1 s gait on a plant carrying `effects` must throw InputError containing must_contain.
void ExpectRunRefused(const std::string& effects, const std::string& out_dir, const std::string& must_contain) {
  Scenario s = ParseScenarioYaml(GaitWith("plant: {effects: " + effects + "}"), "s.yaml");
  s.protocol.duration = 1;
  RunOptions o;
  o.out_dir = out_dir;
  try {
    RunScenario(s, o);
    ADD_FAILURE() << effects << " carried";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(must_contain), std::string::npos) << e.what();
  }
}

TEST(PlantScenario, TheBlockIsReadOrRefusedNamingTheKey) {
  const Scenario s = ParseScenarioYaml(
      GaitWith("plant: {effects: [{name: coulomb_friction, joint: knee, value: 2}, "
               "{name: viscous_friction, joint: hip, value: 0.5}]}"),
      "dir/s.yaml");
  ASSERT_EQ(s.plant_effects.size(), 2u);
  EXPECT_EQ(s.plant_effects[1].name, "viscous_friction");
  EXPECT_EQ(s.plant_effects_source, "dir/s.yaml: plant.effects");
  ExpectScenarioError(GaitWith("plant: {effects_from: missing_extended.yaml}"),
                      "dir/s.yaml: plant.effects_from: file 'dir/missing_extended.yaml' not found");
  ExpectScenarioError(GaitWith("plant: {effects: [{name: coulomb_friction, joint: ankle, value: 2}]}"),
                      "plant.effects[0].joint");
  ExpectScenarioError(GaitWith("plant: {effects: [], effects_from: x.yaml}"), "plant: expected one of");
  ExpectScenarioError(GaitWith("plant: {effect: []}"), "plant");
  // effects_from: relative to the scenario's folder, the model file's effect list.
  const testing::ScopedTempDir tmp("plant_scenario");
  std::ofstream(tmp.path() + "/extended.yaml")
      << "L1: 0.3\nexo: {J1: 0.13, J2: 0.024, X1: 0.35, X2: 0.11, Y1: 0, Y2: 0}\n"
         "effects: [{name: inertia_error, joint: knee, value: 0.01}]\n";
  const Scenario f = ParseScenarioYaml(GaitWith("plant: {effects_from: extended.yaml}"), tmp.path() + "/s.yaml");
  ASSERT_EQ(f.plant_effects.size(), 1u);
  EXPECT_EQ(f.plant_effects[0].name, "inertia_error");
  // Refused when the run builds the plant, naming the effect: a sensor delay that is not a whole
  // number of the joint modules' 1 ms samples, an effect the plant cannot carry.
  ExpectRunRefused("[{name: sensor_delay, joint: knee, value: 0.0005}]", tmp.path() + "/delay",
                   "sensor_delay 0.000500 s of the knee: expected a whole number");
  ExpectRunRefused("[{name: muscle_activity, joint: knee, value: 1}]", tmp.path() + "/run",
                   "s.yaml: plant.effects: effects[0] (muscle_activity, knee)");
}

// Terms in a run's plant (DESIGN.md "Terms beyond the table"): "sgn(qd)" and a ripple's formula as
// terms give the run of coulomb_friction and torque_ripple bit for bit (the same carriers); a
// load-dependent friction changes the run; a sensor-stage term is refused naming the effect.
TEST(PlantScenario, TermsInTheRunsPlant) {
  const testing::ScopedTempDir tmp("plant_terms");
  auto run = [&](const std::string& effects, const std::string& dir) {
    Scenario s = ParseScenarioYaml(GaitWith("plant: {effects: " + effects + "}"), kSrc + "/scenarios/gait_2kmh.yaml");
    s.protocol.duration = 3;
    RunOptions o;
    o.out_dir = tmp.path() + "/" + dir;
    RunScenario(s, o);
    return ReadMeasuredCsv(o.out_dir + "/measured.csv");
  };
  const MeasuredData table = run("[{name: coulomb_friction, joint: knee, value: 0.5}, {name: torque_ripple, joint: hip, "
                                 "value: 0.4, cycles_per_rad: 3, phase: 0.2}]", "table");
  const MeasuredData terms = run("[{name: term, joint: knee, value: 0.5, expr: \"sgn(qd)\"}, {name: term, joint: hip, "
                                 "value: 0.4, expr: \"sin(2 * 3.141592653589793 * 3 * q + 0.2)\"}]", "terms");
  const MeasuredData load = run("[{name: term, joint: knee, value: 0.05, expr: \"abs(tau_R) * sgn(qd)\"}]", "load");
  EXPECT_EQ(terms.q_knee(), table.q_knee());
  EXPECT_EQ(terms.tau_knee(), table.tau_knee());
  EXPECT_EQ(terms.q_hip(), table.q_hip());
  EXPECT_NE(load.tau_knee(), table.tau_knee());
  ExpectRunRefused("[{name: term, joint: knee, value: 0.01, expr: \"tau_R\", stage: sensor}]", tmp.path() + "/sensor",
                   "a sensor-stage term (\"tau_R\") at the knee");
}

// 20 s of the shipped gait (as tests/runner/runner_test.cc) on the rigid plant and on a plant whose
// knee carries 2 N m of Coulomb friction; diagnose with the rigid subject model (examples/S1.yaml,
// the S1 preset's parameters) names the friction within 15 % (measured: 2.000 N m on 60 s) and
// nothing else, and nothing on the rigid plant's record.
TEST(PlantScenario, KneeFrictionInThePlantIsWhatDiagnoseNames) {
  const testing::ScopedTempDir tmp("plant_friction");
  const LegParams rigid_model = ReadModelFile(kSrc + "/examples/S1.yaml");
  for (const bool friction : {false, true}) {
    Scenario s = ParseScenarioYaml(
        GaitWith(friction ? "plant: {effects: [{name: coulomb_friction, joint: knee, value: 2.0}]}" : ""),
        kSrc + "/scenarios/gait_2kmh.yaml");
    s.protocol.duration = 20;
    RunOptions o;
    o.out_dir = tmp.path() + (friction ? "/friction" : "/rigid");
    const RunResult r = RunScenario(s, o);
    std::printf("%s plant: tracking RMS hip %.3f knee %.3f deg; torque RMS hip %.2f knee %.2f N m, max knee %.2f N m\n",
                friction ? "knee friction 2 N m" : "rigid", r.metrics.at("tracking_rms_hip_deg"),
                r.metrics.at("tracking_rms_knee_deg"), r.metrics.at("torque_rms_hip"), r.metrics.at("torque_rms_knee"),
                r.metrics.at("torque_max_knee"));
    EXPECT_LT(r.metrics.at("tracking_rms_knee_deg"), 1.0);
    DiagnoseOptions opt;
    opt.simulate = false;
    const Diagnosis d = Diagnose(rigid_model, ReadMeasuredCsv(o.out_dir + "/measured.csv"), opt);
    for (const auto& e : d.effects)
      std::printf("  named %s (%s) = %.4g %s\n", e.effect.name.c_str(), e.effect.joint.c_str(), e.effect.value,
                  e.effect.unit.c_str());
    if (!friction) {
      EXPECT_TRUE(d.effects.empty());
      continue;
    }
    ASSERT_EQ(d.effects.size(), 1u);
    EXPECT_EQ(d.effects[0].effect.name, "coulomb_friction");
    EXPECT_EQ(d.effects[0].effect.joint, "knee");
    EXPECT_NEAR(d.effects[0].effect.value, 2.0, 0.15 * 2.0);
  }
}

// Runs 20 s of the shipped gait on a plant carrying `effects` (a YAML list) and diagnoses the record
// with the rigid subject model: every effect carried must be named within `tolerance` (relative) and
// nothing else.
void ExpectNamed(const std::string& effects, double tolerance, const std::string& out_dir) {
  const LegParams rigid_model = ReadModelFile(kSrc + "/examples/S1.yaml");
  Scenario s = ParseScenarioYaml(GaitWith("plant: {effects: " + effects + "}"), kSrc + "/scenarios/gait_2kmh.yaml");
  s.protocol.duration = 20;
  RunOptions o;
  o.out_dir = out_dir;
  const RunResult r = RunScenario(s, o);
  DiagnoseOptions opt;
  opt.simulate = false;
  const Diagnosis d = Diagnose(rigid_model, ReadMeasuredCsv(o.out_dir + "/measured.csv"), opt);
  for (const auto& e : d.effects)
    std::printf("  %s: named %s (%s) = %.4g %s; tracking RMS knee %.3f deg\n", effects.c_str(), e.effect.name.c_str(),
                e.effect.joint.c_str(), e.effect.value, e.effect.unit.c_str(), r.metrics.at("tracking_rms_knee_deg"));
  EXPECT_EQ(d.effects.size(), s.plant_effects.size()) << effects;
  for (const Effect& truth : s.plant_effects) {
    const DiagnosedEffect* found = nullptr;
    for (const auto& e : d.effects)
      if (e.effect.name == truth.name && e.effect.joint == truth.joint) found = &e;
    ASSERT_NE(found, nullptr) << effects << ": " << truth.name << " (" << truth.joint << ") not named";
    std::printf("%-17s %-5s truth %.4g named %.4g (%+.1f %%)\n", truth.name.c_str(), truth.joint.c_str(), truth.value,
                found->effect.value, 100 * (found->effect.value / truth.value - 1));
    EXPECT_NEAR(found->effect.value, truth.value, tolerance * std::abs(truth.value)) << effects;
  }
}

// Hidden-effect cases from the forward plant (closed loop: the shipped controller tracking the gait
// on a plant carrying the effects, its joint modules' torque sensors the sensor effects, 20 s each):
// diagnose with the rigid model names every effect carried within 10 % and nothing else (the
// inverse-dynamics cases are in tests/diagnosis/diagnose_hidden_effect_test.cc; measured: within
// 1.8 %).
TEST(PlantScenario, EffectsCarriedByTheForwardPlantAreNamed) {
  const testing::ScopedTempDir tmp("plant_hidden");
  const std::vector<std::string> cases = {
      "[{name: viscous_friction, joint: hip, value: 3.0}]",
      "[{name: inertia_error, joint: knee, value: 0.05}]",
      "[{name: gravity_error, joint: knee, axis: X, value: 0.1}]",
      "[{name: joint_stiffness, joint: knee, value: 5.0, q0: -0.3}]",
      "[{name: coulomb_friction, joint: hip, value: 3.0}, {name: viscous_friction, joint: knee, value: 1.0}]",
      // torque-sensor effects, carried by the joint modules' sensors
      "[{name: sensor_offset, joint: knee, value: 1.5}]",
      "[{name: sensor_gain, joint: hip, value: 0.05}]",
      "[{name: sensor_delay, joint: knee, value: 0.005}]"};
  for (size_t k = 0; k < cases.size(); ++k) ExpectNamed(cases[k], 0.1, tmp.path() + "/case" + std::to_string(k));
}

// Records of the shipped gait (10 s, closed loop) on a plant carrying a knee dead band or a knee strap
// (the internal hinges, sim/internal_joints.h), replayed in 0.5 s windows (diagnosis/replay.h) by the
// rigid subject model and by the model carrying the same effect: the twin with the effect follows
// the record's angles closer (measured: backlash 0.005 rad knee 0.201 -> 0.137 deg, strap
// 300 N m/rad knee 1.060 -> 0.189 deg RMS, 0.7 s); not exactly: the records carry the torque sensor's noise.
TEST(PlantScenario, ReplayOfABacklashOrStrapRecordFollowsItWithTheEffect) {
  const testing::ScopedTempDir tmp("plant_internal_replay");
  const LegParams rigid_model = ReadModelFile(kSrc + "/examples/S1.yaml");
  const std::vector<std::string> cases = {"{name: backlash, joint: knee, value: 0.005}",
                                          "{name: series_compliance, joint: knee, value: 300}"};
  const double gain_at_least[2] = {0.2, 0.6};
  for (size_t k = 0; k < cases.size(); ++k) {
    Scenario s = ParseScenarioYaml(GaitWith("plant: {effects: [" + cases[k] + "]}"), kSrc + "/scenarios/gait_2kmh.yaml");
    s.protocol.duration = 10;
    RunOptions o;
    o.out_dir = tmp.path() + "/case" + std::to_string(k);
    RunScenario(s, o);
    const MeasuredData record = ReadMeasuredCsv(o.out_dir + "/measured.csv");
    double rmse[2];
    for (const bool with_effect : {false, true}) {
      LegParams model = rigid_model;
      if (with_effect) model.effects = s.plant_effects;
      PlantEffects fx;
      auto plant = MakeReplayPlant(model, "model", "", &fx);
      const ReplayRecord r = Replay(*plant, ReplaySeriesOf(record, fx, ReplayInput::kTorque, kReplayCutoffHz), 0.5);
      rmse[with_effect] = r.score.Rmse(1);
    }
    std::printf("%s: replay RMS knee rigid %.3f deg, with the effect %.3f deg\n", cases[k].c_str(), rmse[0] * 180 / M_PI,
                rmse[1] * 180 / M_PI);
    EXPECT_LT(rmse[1], (1 - gain_at_least[k]) * rmse[0]) << cases[k];
  }
}

}  // namespace
}  // namespace exotwin
