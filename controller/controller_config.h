// The controller's configuration as the deployable controller reads it (exotwin-controller --config)
// and as the scenario runner reads a scenario's `controller:` block: one parser for both, below the
// runner (DESIGN.md "Controller file"). Set-up code: throws InputError naming the file and the key.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "controller/exo_controller.h"
#include "controller/hal_loop.h"
#include "controller/trajectory.h"
#include "core/yaml_fields.h"
#include "model/lumped_params.h"

namespace exotwin {

// A scenario's `controller:` block (and a controller file's).
struct ControllerSpec {
  double rate_hz = 1000;
  double kp[2] = {600, 400};   // N m/rad
  double kd[2] = {30, 15};     // N m s/rad
  bool feedforward = true;     // inverse-dynamics feed-forward from the controller's own model
  double torque_limit = 100;   // N m, supervisor limit
};

// The `controller:` line of a scenario or controller file for *c (numbers with 17 significant digits).
std::string ControllerSpecYaml(const ControllerSpec& c);

// Reads the `controller:` mapping `n` (key prefix "controller") into *c; keys absent keep *c's values.
// With require_gains, kp and kd must be given (a controller file: no gains are assumed).
void ParseControllerSpec(const YamlContext& r, const YAML::Node& n, ControllerSpec* c, bool require_gains = false);

namespace controller {

enum class ReferenceKind { kGait, kExcitation, kHold, kSamples };

// The reference the controller tracks (a scenario's protocol and fixed_joints).
struct ReferenceSpec {
  ReferenceKind kind = ReferenceKind::kGait;
  double stride_period = 2.0;          // s (gait)
  std::string moving_joint = "both";   // excitation: hip | knee | both
  uint64_t excitation_seed = 1;
  double ramp = 1.0;                   // s: fade-in from the start pose to the trajectory
  std::optional<double> hold_hip, hold_knee;  // rad, held angles of the joints not moved
  // kSamples: a recorded motion (a scenario's `trajectory: file`, read by the runner) as samples
  // every sample_dt s, played by TabulatedTrajectory (looped, or the last sample held).
  double sample_dt = 0;                        // s
  std::vector<double> sample_hip, sample_knee;  // rad
  bool sample_loop = true;
  double sample_cutoff = 20;                   // Hz, low-pass of the samples' derivatives
};

// The reference of trial `trial` (0-based): gait (Winter, knee shifted by -3 deg to the exoskeleton's
// stop), the identification excitation of the moving joint(s) with the others held (pi/2, -pi/2 by
// default), a hold (0.3, -0.5 rad by default) or recorded samples; faded in over `ramp` s.
std::shared_ptr<const LegTrajectory> BuildReference(const ReferenceSpec& r, int trial);

// Everything the deployable controller needs: gains and limits, the drivers' range, its feed-forward
// model and the reference (EXOwheel); or, with `hal`, the HAL-3 knee loop's whole configuration
// (mode, EMG calibration HKS05 eq. 2, RLS HKS05 eq. 8-13, tau_c of Lee & Sankai), which then replaces
// the gains, model and reference.
struct ControllerFile {
  std::string source;
  ControllerSpec controller;
  double driver_limit = 120;  // N m, the joint modules' torque range (hardware.torque_limit)
  LegParams model;            // the feed-forward model (exoskeleton + the controller's estimate of the subject)
  ReferenceSpec reference;
  int trials = 1;
  std::optional<HalLoopConfig> hal;  // a HAL-3 knee controller (controller/hal_loop.h)
};

// The ExoControllerConfig of a controller file: gains, rate, supervisor limits (sensor range
// min(115, driver_limit) N m, command limit torque_limit, qd 8 rad/s) and the feed-forward model.
ExoControllerConfig ExoConfigOf(const ControllerFile& f);

// Reads a controller file (DESIGN.md "Controller file"); a `hal:` mapping makes it a HAL-3 controller
// (kp, kd and model then not required; controller.torque_limit bounds hal.tau_max). A scenario file (it has `device:`) is refused
// with a message pointing to the controller file `exotwin serve` writes, since a scenario's feed-forward
// model is the twin's to compute (it takes the subject's anthropometry). Throws InputError naming the
// file and key: missing gains or model, controller.torque_limit above drivers.torque_limit, ...
ControllerFile ReadControllerFile(const std::string& path);
ControllerFile ParseControllerFile(const std::string& text, const std::string& source);

// The YAML text of `f` (numbers with 17 significant digits, so reading it back gives the same doubles).
std::string ControllerFileYaml(const ControllerFile& f, const std::string& comment);

}  // namespace controller
}  // namespace exotwin
