#include "runner/scenario.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace exotwin {
namespace {

const char kGood[] = R"(
name: knee_excitation
seed: 7
device: exowheel
subject: {preset: S3}
fixed_joints: {hip: 1.5708}
protocol: {trajectory: excitation, duration: 40, trials: 5, moving_joint: knee}
hardware: {can_drop_rate: 0.01, torque_sensor_offset: [0.1, -0.2], torque_sensor_skew: -2}
controller: {kp: [800, 500], kd: [40, 20]}
faults:
  - {type: sensor_stuck, joint: knee, at: 3.5, duration: 1}
checks:
  - {name: tracking, metric: tracking_rms_knee_deg, max: 1.5}
  - {metric: samples, min: 1000}
)";

TEST(Scenario, ParsesEveryField) {
  const Scenario s = ParseScenarioYaml(kGood, "good.yaml");
  EXPECT_EQ(s.name, "knee_excitation");
  EXPECT_EQ(s.seed, 7u);
  EXPECT_EQ(s.subject.preset, "S3");
  EXPECT_NEAR(s.fixed_joints.at("hip"), 1.5708, 1e-12);
  EXPECT_EQ(s.protocol.trajectory, TrajectoryKind::kExcitation);
  EXPECT_EQ(s.protocol.trials, 5);
  EXPECT_EQ(s.protocol.moving_joint, "knee");
  EXPECT_DOUBLE_EQ(s.hardware.can_drop_rate, 0.01);
  EXPECT_DOUBLE_EQ(s.hardware.torque_sensor_offset[1], -0.2);
  EXPECT_EQ(s.hardware.torque_sensor_skew, -2);
  EXPECT_EQ(ParseScenarioYaml("name: x\ndevice: exowheel\nsubject: {preset: S1}\n", "a.yaml").hardware.torque_sensor_skew, 0);
  EXPECT_DOUBLE_EQ(s.controller.kp[0], 800);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_EQ(s.faults[0].type, "sensor_stuck");
  EXPECT_DOUBLE_EQ(s.faults[0].at, 3.5);
  ASSERT_EQ(s.checks.size(), 2u);
  EXPECT_EQ(s.checks[1].name, "samples");
  EXPECT_EQ(s.checks[1].op, ">=");
}

void ExpectError(const std::string& yaml, const std::string& fragment) {
  try {
    ParseScenarioYaml(yaml, "bad.yaml");
    FAIL() << "expected InputError containing " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Scenario, RejectsBadInput) {
  ExpectError("", "empty scenario");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\ncolour: red\n", "colour: unknown key");
  ExpectError("name: x\ndevice: robot\n", "device: 'robot' is not one of");
  ExpectError("name: x\ndevice: exowheel\n", "subject: missing");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {duration: -1}\n",
              "protocol.duration: value -1 out of range");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {duration: .nan}\n",
              "protocol.duration");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nfaults: [{type: meteor}]\n",
              "faults[0].type: 'meteor' is not one of");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nchecks: [{metric: m}]\n",
              "expected exactly one of max, min");
  ExpectError("name: [x\n", "malformed YAML");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nhardware: {torque_sensor_skew: 1.5}\n",
              "hardware.torque_sensor_skew: expected a whole number of samples, found 1.5 (line 4)");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1, random_seed: 3}\n", "exactly one of");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\ncontroller: {kp: [1]}\n",
              "controller.kp: expected [hip, knee]");
  ExpectError("name: x\ndevice: exowheel\nsubject: {preset: S1}\nhuman: {outward_gate: -0.5}\n",
              "human.outward_gate: value -0.5 out of range");
  // Found by the command-line fuzz (issue 43): a HAL sweep shorter than its settle time had no metrics
  // and died after the run in NormalizeByMax ("internal error").
  ExpectError("name: x\ndevice: hal3\nsubject: {preset: S1}\nprotocol: {duration: 2}\nhal: {sweep_viscosity: [0, 1]}\n",
              "protocol.duration: 2 s leaves no time after hal.settle (4 s) for the metrics");
  ExpectError("name: ../x\ndevice: exowheel\nsubject: {preset: S1}\n", "name: '../x' cannot name a folder");
}

TEST(Scenario, ExaggeratedGaitOutwardGate) {
  const Scenario off = ParseScenarioYaml("name: x\ndevice: exowheel\nsubject: {preset: S1}\n", "a.yaml");
  EXPECT_EQ(off.human.outward_gate, 0.0);  // the amplitude intent unless asked
  const Scenario on = ParseScenarioYaml(
      "name: x\ndevice: exowheel\nsubject: {preset: S1}\nhuman: {behaviour: exaggerated_gait, outward_gate: 2}\n", "b.yaml");
  EXPECT_EQ(on.human.outward_gate, 2.0);
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

TEST(Scenario, RecordedTrajectoryPathIsRelativeToTheScenarioFile) {
  const char yaml[] = "name: x\ndevice: exowheel\nsubject: {preset: S1}\n"
                      "protocol: {trajectory: file, path: motions/walk.mot, side: l, extend: hold, cutoff: 8}\n";
  const Scenario s = ParseScenarioYaml(yaml, "/data/scen/a.yaml");
  EXPECT_EQ(s.protocol.trajectory, TrajectoryKind::kFile);
  EXPECT_EQ(s.protocol.path, "/data/scen/motions/walk.mot");
  EXPECT_EQ(s.protocol.side, "l");
  EXPECT_EQ(s.protocol.extend, "hold");
  EXPECT_DOUBLE_EQ(s.protocol.cutoff, 8.0);
  EXPECT_EQ(ParseScenarioYaml(yaml, "a.yaml").protocol.path, "motions/walk.mot");  // beside a.yaml in the cwd
  const Scenario d = ParseScenarioYaml("name: x\ndevice: exowheel\nsubject: {preset: S1}\n"
                                       "protocol: {trajectory: file, path: /abs/w.sto}\n", "s/a.yaml");
  EXPECT_EQ(d.protocol.path, "/abs/w.sto");
  EXPECT_EQ(d.protocol.side, "r");
  EXPECT_EQ(d.protocol.extend, "loop");
  EXPECT_DOUBLE_EQ(d.protocol.cutoff, 20.0);
}

TEST(Scenario, RecordedTrajectoryBadSettings) {
  const std::string head = "name: x\ndevice: exowheel\nsubject: {preset: S1}\n";
  ExpectError(head + "protocol: {trajectory: file}\n", "protocol.path: required");
  ExpectError(head + "protocol: {trajectory: file, path: w.mot, side: x}\n", "protocol.side");
  ExpectError(head + "protocol: {trajectory: file, path: w.mot, extend: mirror}\n", "protocol.extend");
  ExpectError(head + "protocol: {trajectory: gait, path: w.mot}\n", "protocol.path: only with trajectory: file");
  ExpectError(head + "protocol: {trajectory: file, path: w.mot, cutoff: 0}\n", "protocol.cutoff");
}

}  // namespace
}  // namespace exotwin
