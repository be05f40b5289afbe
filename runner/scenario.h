// A scenario file (YAML): subject, device, protocol, hardware settings and faults, logs and checks.
// DESIGN.md holds the schema; scenarios/*.yaml are the shipped examples.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "controller/controller_config.h"  // ControllerSpec: the controller block
#include "model/lumped_params.h"

namespace exotwin {

enum class Device { kExowheel, kExowheelExoOnly, kHal3 };
enum class TrajectoryKind { kGait, kExcitation, kHold, kFile };

struct SubjectSpec {
  std::string preset;          // "S1".."S10"
  std::optional<uint64_t> random_seed;  // draw from the population with this seed
  std::string params_file;     // or a MODEL.yaml
  PassiveModel passive = PassiveModel::kRiener1999;
};

struct ProtocolSpec {
  TrajectoryKind trajectory = TrajectoryKind::kGait;
  double duration = 10.0;       // s per trial
  int trials = 1;
  double stride_period = 2.0;   // s (gait)
  std::string moving_joint = "both";  // excitation: hip | knee | both
  uint64_t excitation_seed = 1;
  double ramp = 1.0;            // s: the controller ramps from the start pose to the trajectory
  // trajectory: file (DESIGN.md "OpenSim motion files"): an OpenSim .mot/.sto, its first sample at t = 0
  std::string path;             // as resolved: relative paths are relative to the scenario file's folder
  std::string side = "r";       // r | l: hip_flexion_<side>, knee_angle_<side>
  std::string extend = "loop";  // loop (the file holds one stride, repeated) | hold (last pose at rest)
  double cutoff = 20.0;         // Hz, the derivative filter of the recorded angles (HJ15 sec. 3.2)
};

// One injected fault: `type` as in hwsim (sensor_stuck, sensor_stale, encoder_glitch, frame_drop,
// frame_late, bus_off, command_loss, nan_measurement), on `joint` (hip/knee/all), from `at` (s) for
// `duration` (s, <= 0 = until the end), with a type-specific `value`.
struct FaultSpec {
  std::string type;
  std::string joint = "all";
  double at = 0;
  double duration = 0;
  double value = 0;
};

// The subject's behaviour and EMG (EXOwheel devices with a subject).
struct HumanSpec {
  std::string behaviour = "relaxed";  // relaxed | exaggerated_gait | isometric_hip | isometric_knee
  double active_from = 5.0;           // s: exaggerated gait starts here (relaxed before, as Fig. 9)
  double gain = 1.3;                  // exaggerated gait: amplification of the pattern
  double outward_gate = 0.0;          // exaggerated gait: ExaggeratedGait's outward gate s0 (rad^2/s; 0 = off)
  int contractions = 6;               // isometric programmes: number of contractions
  double levels[2] = {0.2, 0.8};      // isometric programmes: contraction levels, fraction of MVC
  double cocontraction = 0.1;         // isometric programmes: antagonist drive / agonist level
  std::optional<uint64_t> programme_seed;  // isometric programmes: seed (default: from the run seed)
  bool emg = true;                    // EMG electrodes + amplifier node on the bus
  uint64_t muscle_seed = 1;           // ground-truth alpha, beta, gamma drawn from Tables 6-7
};

// Hwang & Jeon 2015 sec. 4.3 EMG-to-torque calibration run as one scenario (EXOwheel with a
// subject; runner/emg_calibration_protocol.h): MVC trials, isometric trials per joint (HJ15 eq. 25)
// and, with `dynamic`, the exaggerated gait (HJ15 eq. 28) evaluated with three parameter sets.
struct EmgCalibrationSpec {
  bool dynamic = true;                  // run the gait trial and fit beta, gamma (Table 7)
  int mvc_trials = 3;                   // MVC trials per muscle (paper: 3)
  double hip_pose[2] = {0.0, 0.0};      // rad (hip, knee) held for hip isometric trials (Fig. 7a)
  double knee_pose[2] = {0.7854, -1.5707963267948966};  // rad, knee trials (Fig. 7b; see yaml)
  int strides = 10;                     // gait strides after human.active_from (paper: 10)
  // > 1: the protocol on Table 4's subjects S1..S<subjects>, muscle ground truth human.muscle_seed + i - 1;
  // result metrics are the means over the subjects (worst case for *max*, *min*, safe_state_entered),
  // plus *_sd and per-subject "subject_S<i>.<metric>".
  int subjects = 1;
  // Samples of the HJ15 eq. 28 fit and of Table 7's R^2: "active" = the exaggerated strides only
  // (human.active_from .. the last stride); "trial" = the whole gait trial after the controller's
  // fade-in, so the relaxed lead-in (Fig. 9: relaxed up to 5 s, tau_M ~ 0 with the identified set)
  // is part of the comparison, as Fig. 9-d shows it.
  std::string fit_window = "active";
};

// HAL-3 settings (device: hal3 only; runner/hal_runner.h). The operator performs Hayashi's seated
// 0.5 Hz knee swing (targets +1.0 / -0.3 rad) with co-contraction cc_down in swing-down.
struct HalSpec {
  std::string mode = "impedance";   // none | impedance (tau_c only: Hayashi exp. 1, Lee & Sankai) | assist (exp. 2)
  double alpha_mu = 1.0;            // HKS05 eq. 3
  double alpha_zeta = 0.5;          // HKS05 eq. 5
  double virtual_viscosity = 0.0;   // B_v of tau_c, N m s/rad (Lee & Sankai; 0 = Hayashi's tau_c)
  std::vector<double> sweep_viscosity;  // non-empty: one run per B_v (replaces protocol.trials)
  double swing_freq = 0.5;          // Hz
  double cc_up = 0.0, cc_down = 0.05;  // co-contraction drive (fraction of MVC) outside / in swing-down
  bool cc_synergy = false;          // TrackingGains::cocontraction_synergy (mix within each group)
  // HKS05 eq. 2 calibration exercise (runner/hal_emg_calibration.h): contraction levels per direction
  // from 2 % to calibration_hi of MVC, and the relaxed rest (s) that gives the baselines.
  int calibration_levels = 4;
  double calibration_hi = 0.12;
  double calibration_rest = 1.5;
  double settle = 4.0;              // s at the start excluded from the metrics
  bool rls_gravity_in_input = true; // ViscoelasticRlsConfig::gravity_in_input
  bool rls_known_inertia = false;   // ViscoelasticRlsConfig::known_inertia (I from HKS05 eq. 14)
  bool rls_friction_in_input = false;  // HalAssistConfig::friction_C = the actuator's C (HKS05 eq. 15)
  double operator_delay = 0.0;      // s, neural delay of the operator's feedback (TrackingGains::feedback_delay)
};

struct CheckSpec {
  std::string name;
  std::string metric;
  double limit = 0;
  std::string op = "<=";  // "<=" (value must not exceed limit) or ">="
};

struct HardwareSpec {
  double can_bitrate = 1e6;         // bit/s
  double can_latency = 50e-6;       // s, per frame in the controller interface
  double can_jitter = 10e-6;        // s, standard deviation
  double can_drop_rate = 0;         // probability per frame
  double torque_sensor_noise = 0.024;  // N m (0.02 % FS repeatability of the +-120 N m sensor)
  double torque_sensor_offset[2] = {0, 0};  // N m
  int encoder_bits = 19;            // counts per revolution = 2^bits
  double motor_lag = 0.5e-3;        // s, current-loop time constant
  double torque_limit = 120;        // N m, driver saturation
  double watchdog = 0.02;           // s without a command -> driver cuts torque
  int torque_sensor_skew = 0;       // samples, torque sensor older than the angle sensor (< 0: younger);
                                    // JointModuleSpec / Hal3KneeNodeSpec::torque_sensor_skew
};

struct Scenario {
  std::string name;
  std::string source;  // file path, for messages
  SubjectSpec subject;
  HumanSpec human;
  HalSpec hal;
  std::optional<EmgCalibrationSpec> emg_calibration;
  Device device = Device::kExowheel;
  std::map<std::string, double> fixed_joints;  // joint -> angle (rad)
  ProtocolSpec protocol;
  HardwareSpec hardware;
  ControllerSpec controller;
  std::vector<FaultSpec> faults;
  bool log_measured_csv = true;
  double log_rate_hz = 1000;
  std::vector<CheckSpec> checks;
  uint64_t seed = 1;
  // plant: {effects: [...]} or {effects_from: FILE.yaml} (EXOwheel devices): effects the forward
  // plant carries (sim/plant_effects.h) on top of the subject's rigid twin.
  std::vector<Effect> plant_effects;
  std::string plant_effects_source;  // where they were read ("<scenario>: plant.effects" or the file)
};

// Reads and validates a scenario file. Throws InputError naming the file, the key and what was
// expected (text that is not UTF-8, unknown keys, wrong types, out-of-range values, unknown names, a
// check's metric the run cannot report: runner/scenario_metrics.h).
Scenario ReadScenario(const std::string& path);
Scenario ParseScenarioYaml(const std::string& text, const std::string& source);

const char* DeviceName(Device d);

}  // namespace exotwin
