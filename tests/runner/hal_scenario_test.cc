// The optional hal: block of a scenario file (device: hal3): every field, and strict rejection.
#include <gtest/gtest.h>

#include "core/error.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

const char kHal[] = R"(
name: hal_sweep
device: hal3
subject: {preset: S1}
protocol: {duration: 6}
hal: {mode: assist, alpha_mu: 0.8, alpha_zeta: 0.4, virtual_viscosity: 1.2, sweep_viscosity: [0, 1.56, 3],
      swing_freq: 0.6, cc_up: 0.01, cc_down: 0.08, settle: 2.5, rls_gravity_in_input: false,
      rls_known_inertia: true, rls_friction_in_input: true, cc_synergy: true, calibration_levels: 9,
      calibration_hi: 0.25, calibration_rest: 4.5}
)";

// The twin's extensions of Hayashi's method (all on or all off here) and the calibration exercise.
void ExpectExtensions(const Scenario& s, bool on, int levels, double hi, double rest) {
  EXPECT_EQ(s.hal.rls_known_inertia, on);
  EXPECT_EQ(s.hal.rls_friction_in_input, on);
  EXPECT_EQ(s.hal.cc_synergy, on);
  EXPECT_EQ(s.hal.calibration_levels, levels);
  EXPECT_DOUBLE_EQ(s.hal.calibration_hi, hi);
  EXPECT_DOUBLE_EQ(s.hal.calibration_rest, rest);
}

TEST(HalScenario, ParsesEveryField) {
  const Scenario s = ParseScenarioYaml(kHal, "hal.yaml");
  EXPECT_EQ(s.device, Device::kHal3);
  EXPECT_EQ(s.hal.mode, "assist");
  EXPECT_DOUBLE_EQ(s.hal.alpha_mu, 0.8);
  EXPECT_DOUBLE_EQ(s.hal.alpha_zeta, 0.4);
  EXPECT_DOUBLE_EQ(s.hal.virtual_viscosity, 1.2);
  ASSERT_EQ(s.hal.sweep_viscosity.size(), 3u);
  EXPECT_DOUBLE_EQ(s.hal.sweep_viscosity[1], 1.56);
  EXPECT_DOUBLE_EQ(s.hal.swing_freq, 0.6);
  EXPECT_DOUBLE_EQ(s.hal.cc_up, 0.01);
  EXPECT_DOUBLE_EQ(s.hal.cc_down, 0.08);
  EXPECT_DOUBLE_EQ(s.hal.settle, 2.5);
  EXPECT_FALSE(s.hal.rls_gravity_in_input);
  ExpectExtensions(s, true, 9, 0.25, 4.5);
}

TEST(HalScenario, DefaultsWithoutBlock) {
  const Scenario s = ParseScenarioYaml("name: x\ndevice: hal3\nsubject: {preset: S1}\n", "x.yaml");
  EXPECT_EQ(s.hal.mode, "impedance");
  EXPECT_DOUBLE_EQ(s.hal.alpha_mu, 1.0);
  EXPECT_DOUBLE_EQ(s.hal.alpha_zeta, 0.5);
  EXPECT_TRUE(s.hal.sweep_viscosity.empty());
  ExpectExtensions(s, false, 4, 0.12, 1.5);  // the paper's method unless asked otherwise
}

void ExpectRejected(const std::string& hal_line, const std::string& needle, const std::string& device = "hal3") {
  const std::string text = "name: x\ndevice: " + device + "\nsubject: {preset: S1}\n" + hal_line + "\n";
  try {
    ParseScenarioYaml(text, "bad.yaml");
    ADD_FAILURE() << "accepted: " << hal_line;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
  }
}

TEST(HalScenario, RejectsBadInput) {
  ExpectRejected("hal: {mode: turbo}", "hal.mode");
  ExpectRejected("hal: {alpha_mu: -1}", "hal.alpha_mu");
  ExpectRejected("hal: {alpha_zeta: abc}", "hal.alpha_zeta");
  ExpectRejected("hal: {virtual_viscosity: 100}", "hal.virtual_viscosity");
  ExpectRejected("hal: {sweep_viscosity: 1.0}", "hal.sweep_viscosity");
  ExpectRejected("hal: {sweep_viscosity: [1.0]}", "hal.sweep_viscosity");
  ExpectRejected("hal: {sweep_viscosity: [0, x]}", "hal.sweep_viscosity[1]");
  ExpectRejected("hal: {swing_freq: 0}", "hal.swing_freq");
  ExpectRejected("hal: {cc_down: 2}", "hal.cc_down");
  ExpectRejected("hal: {rls_gravity_in_input: maybe}", "hal.rls_gravity_in_input");
  ExpectRejected("hal: {rls_known_inertia: 2}", "hal.rls_known_inertia");
  ExpectRejected("hal: {rls_friction_in_input: yes please}", "hal.rls_friction_in_input");
  ExpectRejected("hal: {cc_synergy: 0.5}", "hal.cc_synergy");
  ExpectRejected("hal: {calibration_levels: 1}", "hal.calibration_levels");
  ExpectRejected("hal: {calibration_hi: 0.01}", "hal.calibration_hi");
  ExpectRejected("hal: {calibration_rest: 100}", "hal.calibration_rest");
  ExpectRejected("hal: {gain: 1}", "unknown key");
  ExpectRejected("hal: [1, 2]", "hal");
  ExpectRejected("hal: {mode: assist}", "only allowed with device: hal3", "exowheel");
}

}  // namespace
}  // namespace exotwin
