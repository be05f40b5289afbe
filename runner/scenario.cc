#include "runner/scenario.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.h"
#include "formats/model_file.h"
#include "formats/number_text.h"
#include "core/yaml_fields.h"
#include "runner/scenario_metrics.h"
#include "sim/subjects.h"

namespace exotwin {

const char* DeviceName(Device d) {
  switch (d) {
    case Device::kExowheel: return "exowheel";
    case Device::kExowheelExoOnly: return "exowheel_exo_only";
    case Device::kHal3: return "hal3";
  }
  return "?";
}

namespace {


const std::set<std::string> kFaultTypes = {"sensor_stuck", "sensor_stale", "encoder_glitch", "frame_drop",
                                           "frame_late",   "bus_off",      "command_loss",   "nan_measurement"};

void ParseHal(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  if (s.device != Device::kHal3) r.Fail("hal", "only allowed with device: hal3");
  YamlCheckKeys(r, n, "hal", {"mode", "alpha_mu", "alpha_zeta", "virtual_viscosity", "sweep_viscosity", "swing_freq",
                    "cc_up", "cc_down", "settle", "rls_gravity_in_input", "rls_known_inertia",
                    "operator_delay", "cc_synergy", "rls_friction_in_input", "calibration_levels",
                    "calibration_hi", "calibration_rest"});
  HalSpec& h = s.hal;
  if (n["mode"]) h.mode = YamlString(r, n["mode"], "hal.mode", {"none", "impedance", "assist"});
  if (n["alpha_mu"]) h.alpha_mu = YamlNumber(r, n["alpha_mu"], "hal.alpha_mu", 0, 5);
  if (n["alpha_zeta"]) h.alpha_zeta = YamlNumber(r, n["alpha_zeta"], "hal.alpha_zeta", 0, 5);
  if (n["virtual_viscosity"]) h.virtual_viscosity = YamlNumber(r, n["virtual_viscosity"], "hal.virtual_viscosity", -5, 20);
  if (n["sweep_viscosity"]) {
    const YAML::Node v = n["sweep_viscosity"];
    if (!v.IsSequence() || v.size() < 2 || v.size() > 50)
      r.Fail("hal.sweep_viscosity", "expected a list of 2..50 viscosities (N m s/rad)" + YamlLine(v));
    for (size_t i = 0; i < v.size(); ++i)
      h.sweep_viscosity.push_back(YamlNumber(r, v[i], "hal.sweep_viscosity[" + std::to_string(i) + "]", -5, 20));
  }
  if (n["swing_freq"]) h.swing_freq = YamlNumber(r, n["swing_freq"], "hal.swing_freq", 0.1, 2);
  if (n["cc_up"]) h.cc_up = YamlNumber(r, n["cc_up"], "hal.cc_up", 0, 1);
  if (n["cc_down"]) h.cc_down = YamlNumber(r, n["cc_down"], "hal.cc_down", 0, 1);
  if (n["settle"]) h.settle = YamlNumber(r, n["settle"], "hal.settle", 0, 3600);
  if (n["operator_delay"]) h.operator_delay = YamlNumber(r, n["operator_delay"], "hal.operator_delay", 0, 0.3);
  if (n["rls_gravity_in_input"]) h.rls_gravity_in_input = YamlBool(r, n["rls_gravity_in_input"], "hal.rls_gravity_in_input");
  if (n["calibration_levels"]) h.calibration_levels = static_cast<int>(YamlNumber(r, n["calibration_levels"], "hal.calibration_levels", 2, 50));
  if (n["calibration_hi"]) h.calibration_hi = YamlNumber(r, n["calibration_hi"], "hal.calibration_hi", 0.05, 1);
  if (n["calibration_rest"]) h.calibration_rest = YamlNumber(r, n["calibration_rest"], "hal.calibration_rest", 0.5, 60);
  if (n["rls_friction_in_input"])
    h.rls_friction_in_input = YamlBool(r, n["rls_friction_in_input"], "hal.rls_friction_in_input");
  if (n["cc_synergy"]) h.cc_synergy = YamlBool(r, n["cc_synergy"], "hal.cc_synergy");
  if (n["rls_known_inertia"]) h.rls_known_inertia = YamlBool(r, n["rls_known_inertia"], "hal.rls_known_inertia");
}

void ParseEmgCalibration(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  if (s.device != Device::kExowheel) r.Fail("emg_calibration", "only allowed with device: exowheel");
  YamlCheckKeys(r, n, "emg_calibration", {"dynamic", "mvc_trials", "hip_pose", "knee_pose", "strides", "subjects", "fit_window"});
  EmgCalibrationSpec c;
  if (n["dynamic"]) c.dynamic = YamlBool(r, n["dynamic"], "emg_calibration.dynamic");
  if (n["mvc_trials"]) c.mvc_trials = static_cast<int>(YamlNumber(r, n["mvc_trials"], "emg_calibration.mvc_trials", 1, 10));
  if (n["hip_pose"]) YamlNumberPair(r, n["hip_pose"], "emg_calibration.hip_pose", c.hip_pose, -2.5, 2.5);
  if (n["knee_pose"]) YamlNumberPair(r, n["knee_pose"], "emg_calibration.knee_pose", c.knee_pose, -2.5, 2.5);
  if (n["strides"]) c.strides = static_cast<int>(YamlNumber(r, n["strides"], "emg_calibration.strides", 1, 100));
  if (n["subjects"]) c.subjects = static_cast<int>(YamlNumber(r, n["subjects"], "emg_calibration.subjects", 1, 10));
  if (n["fit_window"]) c.fit_window = YamlString(r, n["fit_window"], "emg_calibration.fit_window", {"active", "trial"});
  s.emg_calibration = c;
}

// The stages of ParseScenarioYaml, run in this order (a file with several errors reports the first
// stage's). Each reads its block into s and throws InputError naming the key on bad content.

// name (required), seed, device (required).
void ParseHeader(const YamlContext& r, const YAML::Node& root, Scenario& s) {
  if (!root["name"]) r.Fail("name", "missing, expected the scenario's name");
  s.name = YamlString(r, root["name"], "name");
  // The name names folders (sweep's runs/<name>/, regress's <name>/) and files: one plain file name.
  if (s.name.empty() || s.name == "." || s.name == ".." || s.name.find('/') != std::string::npos ||
      s.name.size() > 200 || s.name.find_first_of("\n\r\t") != std::string::npos)
    r.Fail("name", "'" + s.name + "' cannot name a folder, expected a non-empty name of at most 200 bytes without '/', "
                   "tab or line break, other than '.' and '..'" + YamlLine(root["name"]));
  if (root["seed"]) s.seed = static_cast<uint64_t>(YamlNumber(r, root["seed"], "seed", 0, 1e15));

  if (!root["device"]) r.Fail("device", "missing, expected exowheel, exowheel_exo_only or hal3");
  const std::string dev = YamlString(r, root["device"], "device", {"exowheel", "exowheel_exo_only", "hal3"});
  s.device = dev == "exowheel" ? Device::kExowheel
                               : (dev == "hal3" ? Device::kHal3 : Device::kExowheelExoOnly);
}

// subject: exactly one of preset, random_seed, params (+ passive); required unless exowheel_exo_only.
void ParseSubject(const YamlContext& r, const YAML::Node& root, Scenario& s) {
  if (const YAML::Node n = root["subject"]) {
    YamlCheckKeys(r, n, "subject", {"preset", "random_seed", "params", "passive"});
    const int given = !!n["preset"] + !!n["random_seed"] + !!n["params"];
    if (given != 1) r.Fail("subject", "expected exactly one of preset, random_seed, params");
    if (n["preset"]) {
      const std::vector<std::string> presets = PresetNames();
      s.subject.preset = YamlString(r, n["preset"], "subject.preset", {presets.begin(), presets.end()});
    }
    if (n["random_seed"])
      s.subject.random_seed = static_cast<uint64_t>(YamlNumber(r, n["random_seed"], "subject.random_seed", 0, 1e15));
    if (n["params"]) s.subject.params_file = YamlString(r, n["params"], "subject.params");
    if (n["passive"])
      s.subject.passive = YamlString(r, n["passive"], "subject.passive", {"none", "riener1999"}) == "none"
                              ? PassiveModel::kNone
                              : PassiveModel::kRiener1999;
  } else if (s.device != Device::kExowheelExoOnly) {
    r.Fail("subject", "missing, expected {preset: S1} or {random_seed: N} or {params: FILE}");
  }
}

// human: behaviour, its parameters, EMG and the muscles' ground-truth seed.
void ParseHuman(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "human", {"behaviour", "active_from", "gain", "contractions", "levels", "cocontraction",
                      "programme_seed", "emg", "muscle_seed", "outward_gate"});
  HumanSpec& h = s.human;
  if (n["behaviour"])
    h.behaviour = YamlString(r, n["behaviour"], "human.behaviour",
                        {"relaxed", "exaggerated_gait", "isometric_hip", "isometric_knee"});
  if (n["active_from"]) h.active_from = YamlNumber(r, n["active_from"], "human.active_from", 0, 3600);
  if (n["gain"]) h.gain = YamlNumber(r, n["gain"], "human.gain", 0.5, 3);
  if (n["outward_gate"]) h.outward_gate = YamlNumber(r, n["outward_gate"], "human.outward_gate", 0, 100);
  if (n["contractions"]) h.contractions = static_cast<int>(YamlNumber(r, n["contractions"], "human.contractions", 1, 100));
  if (n["levels"]) {
    const YAML::Node v = n["levels"];
    if (!v.IsSequence() || v.size() != 2) r.Fail("human.levels", "expected [lo, hi] (fraction of MVC)" + YamlLine(v));
    h.levels[0] = YamlNumber(r, v[0], "human.levels[0]", 0, 1);
    h.levels[1] = YamlNumber(r, v[1], "human.levels[1]", 0, 1);
    if (!(h.levels[0] <= h.levels[1])) r.Fail("human.levels", "expected [lo, hi] with lo <= hi (fraction of MVC)");
  }
  if (n["cocontraction"]) h.cocontraction = YamlNumber(r, n["cocontraction"], "human.cocontraction", 0, 1);
  if (n["programme_seed"])
    h.programme_seed = static_cast<uint64_t>(YamlNumber(r, n["programme_seed"], "human.programme_seed", 0, 1e15));
  if (n["emg"]) h.emg = YamlBool(r, n["emg"], "human.emg");
  if (n["muscle_seed"]) h.muscle_seed = static_cast<uint64_t>(YamlNumber(r, n["muscle_seed"], "human.muscle_seed", 0, 1e15));
}

// fixed_joints: held angles of the joints an excitation does not move (rad).
void ParseFixedJoints(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "fixed_joints", {"hip", "knee"});
  for (const auto& kv : n) {
    const std::string j = kv.first.as<std::string>();
    s.fixed_joints[j] = YamlNumber(r, kv.second, "fixed_joints." + j, -2.5, 2.5);
  }
}

// plant: the effects the plant carries, listed (effects) or those of a model file (effects_from,
// relative to the scenario file's folder, e.g. diagnose's extended.yaml). EXOwheel devices without
// emg_calibration (the HAL-3 knee and the calibration's trials build other plants).
void ParsePlant(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "plant", {"effects", "effects_from"});
  if (s.device == Device::kHal3) r.Fail("plant", "only allowed with device: exowheel or exowheel_exo_only");
  if (s.emg_calibration) r.Fail("plant", "not used with emg_calibration");
  if (!!n["effects"] == !!n["effects_from"]) r.Fail("plant", "expected one of effects: [...] or effects_from: FILE.yaml");
  if (n["effects"]) {
    s.plant_effects = ReadEffectList(r, n["effects"], "plant.effects");
    s.plant_effects_source = s.source + ": plant.effects";
    return;
  }
  std::string path = YamlString(r, n["effects_from"], "plant.effects_from");
  if (path.empty()) r.Fail("plant.effects_from", "empty (expected a model file, e.g. diagnose's extended.yaml)");
  const size_t slash = s.source.find_last_of('/');
  if (path[0] != '/' && slash != std::string::npos) path = s.source.substr(0, slash + 1) + path;
  if (!std::ifstream(path).good())
    r.Fail("plant.effects_from", "file '" + path + "' not found (expected a model file with effects)" + YamlLine(n["effects_from"]));
  s.plant_effects = ReadModelFile(path).effects;
  s.plant_effects_source = path;
}

// protocol: the recorded trajectory's settings (trajectory: file): path (relative to the scenario
// file's folder), side, extend, cutoff. The file itself is read when the trial is built.
void ParseProtocolFile(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  ProtocolSpec& p = s.protocol;
  const bool file = p.trajectory == TrajectoryKind::kFile;
  for (const char* k : {"path", "side", "extend", "cutoff"})
    if (n[k] && !file) r.Fail(std::string("protocol.") + k, "only with trajectory: file" + YamlLine(n[k]));
  if (!file) return;
  if (!n["path"]) r.Fail("protocol.path", "required with trajectory: file (an OpenSim .mot or .sto motion file)");
  p.path = YamlString(r, n["path"], "protocol.path");
  if (p.path.empty()) r.Fail("protocol.path", "empty (expected an OpenSim .mot or .sto motion file)");
  const size_t slash = s.source.find_last_of('/');
  if (p.path[0] != '/' && slash != std::string::npos) p.path = s.source.substr(0, slash + 1) + p.path;
  if (n["side"]) p.side = YamlString(r, n["side"], "protocol.side", {"r", "l"});
  if (n["extend"]) p.extend = YamlString(r, n["extend"], "protocol.extend", {"loop", "hold"});
  if (n["cutoff"]) p.cutoff = YamlNumber(r, n["cutoff"], "protocol.cutoff", 0.1, 500);
}

// protocol: trajectory, duration, trials and the excitation's settings.
void ParseProtocol(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "protocol", {"trajectory", "duration", "trials", "stride_period", "moving_joint",
                         "excitation_seed", "ramp", "path", "side", "extend", "cutoff"});
  ProtocolSpec& p = s.protocol;
  if (n["trajectory"]) {
    const std::string t =
        YamlString(r, n["trajectory"], "protocol.trajectory", {"gait", "excitation", "hold", "file"});
    p.trajectory = t == "gait" ? TrajectoryKind::kGait
                               : (t == "excitation" ? TrajectoryKind::kExcitation
                                                    : (t == "hold" ? TrajectoryKind::kHold : TrajectoryKind::kFile));
  }
  ParseProtocolFile(r, n, s);
  if (n["duration"]) p.duration = YamlNumber(r, n["duration"], "protocol.duration", 0.01, 3600);
  if (n["trials"]) p.trials = static_cast<int>(YamlNumber(r, n["trials"], "protocol.trials", 1, 100));
  if (n["stride_period"]) p.stride_period = YamlNumber(r, n["stride_period"], "protocol.stride_period", 0.5, 10);
  if (n["moving_joint"]) p.moving_joint = YamlString(r, n["moving_joint"], "protocol.moving_joint", {"hip", "knee", "both"});
  if (n["excitation_seed"])
    p.excitation_seed = static_cast<uint64_t>(YamlNumber(r, n["excitation_seed"], "protocol.excitation_seed", 0, 1e15));
  if (n["ramp"]) p.ramp = YamlNumber(r, n["ramp"], "protocol.ramp", 0, 60);
}

// hardware: CAN bus, sensors, drivers (HardwareSpec).
void ParseHardware(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "hardware", {"can_bitrate", "can_latency", "can_jitter", "can_drop_rate", "torque_sensor_noise",
                         "torque_sensor_offset", "encoder_bits", "motor_lag", "torque_limit", "watchdog",
                         "torque_sensor_skew"});
  HardwareSpec& h = s.hardware;
  if (n["can_bitrate"]) h.can_bitrate = YamlNumber(r, n["can_bitrate"], "hardware.can_bitrate", 10e3, 1e6);
  if (n["can_latency"]) h.can_latency = YamlNumber(r, n["can_latency"], "hardware.can_latency", 0, 0.1);
  if (n["can_jitter"]) h.can_jitter = YamlNumber(r, n["can_jitter"], "hardware.can_jitter", 0, 0.01);
  if (n["can_drop_rate"]) h.can_drop_rate = YamlNumber(r, n["can_drop_rate"], "hardware.can_drop_rate", 0, 1);
  if (n["torque_sensor_noise"])
    h.torque_sensor_noise = YamlNumber(r, n["torque_sensor_noise"], "hardware.torque_sensor_noise", 0, 10);
  if (n["torque_sensor_offset"])
    YamlNumberPair(r, n["torque_sensor_offset"], "hardware.torque_sensor_offset", h.torque_sensor_offset, -120, 120);
  if (n["encoder_bits"]) h.encoder_bits = static_cast<int>(YamlNumber(r, n["encoder_bits"], "hardware.encoder_bits", 8, 24));
  if (n["motor_lag"]) h.motor_lag = YamlNumber(r, n["motor_lag"], "hardware.motor_lag", 0, 0.05);
  if (n["torque_limit"]) h.torque_limit = YamlNumber(r, n["torque_limit"], "hardware.torque_limit", 1, 500);
  if (n["watchdog"]) h.watchdog = YamlNumber(r, n["watchdog"], "hardware.watchdog", 0.002, 1);
  if (n["torque_sensor_skew"]) {
    const double k = YamlNumber(r, n["torque_sensor_skew"], "hardware.torque_sensor_skew", -100, 100);
    if (k != std::round(k))
      r.Fail("hardware.torque_sensor_skew", "expected a whole number of samples, found " + n["torque_sensor_skew"].Scalar() +
                                                   YamlLine(n["torque_sensor_skew"]));
    h.torque_sensor_skew = static_cast<int>(k);
  }
}

// controller: rate, PD gains, feed-forward, supervisor torque limit (the controller's own parser).
void ParseController(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  ParseControllerSpec(r, n, &s.controller);
}

// faults: a list of FaultSpec (null = none).
void ParseFaults(const YamlContext& r, const YAML::Node& list, Scenario& s) {
  if (!list.IsSequence()) r.Fail("faults", "expected a list");
  int i = 0;
  for (const auto& n : list) {
    const std::string key = "faults[" + std::to_string(i++) + "]";
    YamlCheckKeys(r, n, key, {"type", "joint", "at", "duration", "value"});
    FaultSpec f;
    if (!n["type"]) r.Fail(key + ".type", "missing");
    f.type = YamlString(r, n["type"], key + ".type", kFaultTypes);
    if (n["joint"]) f.joint = YamlString(r, n["joint"], key + ".joint", {"hip", "knee", "all"});
    if (n["at"]) f.at = YamlNumber(r, n["at"], key + ".at", 0, 3600);
    if (n["duration"]) f.duration = YamlNumber(r, n["duration"], key + ".duration", 0, 3600);
    if (n["value"]) f.value = YamlNumber(r, n["value"], key + ".value", -1e6, 1e6);
    s.faults.push_back(f);
  }
}

// logs: measured_csv, rate_hz.
void ParseLogs(const YamlContext& r, const YAML::Node& n, Scenario& s) {
  YamlCheckKeys(r, n, "logs", {"measured_csv", "rate_hz"});
  if (n["measured_csv"]) s.log_measured_csv = YamlBool(r, n["measured_csv"], "logs.measured_csv");
  if (n["rate_hz"]) s.log_rate_hz = YamlNumber(r, n["rate_hz"], "logs.rate_hz", 1, 10000);
}

// checks: a list of {metric, name, max | min} (null = none).
void ParseChecks(const YamlContext& r, const YAML::Node& list, Scenario& s) {
  if (!list.IsSequence()) r.Fail("checks", "expected a list");
  int i = 0;
  for (const auto& n : list) {
    const std::string key = "checks[" + std::to_string(i++) + "]";
    YamlCheckKeys(r, n, key, {"name", "metric", "max", "min"});
    CheckSpec c;
    if (!n["metric"]) r.Fail(key + ".metric", "missing, expected a metric name");
    c.metric = YamlString(r, n["metric"], key + ".metric");
    c.name = n["name"] ? YamlString(r, n["name"], key + ".name") : c.metric;
    if (!!n["max"] == !!n["min"]) r.Fail(key, "expected exactly one of max, min");
    if (n["max"]) { c.limit = YamlNumber(r, n["max"], key + ".max", -1e12, 1e12); c.op = "<="; }
    else { c.limit = YamlNumber(r, n["min"], key + ".min", -1e12, 1e12); c.op = ">="; }
    s.checks.push_back(c);
  }
}

// With emg_calibration: the blocks it needs (subject with weight and lengths, EMG) and the ones it sets itself.
void CheckEmgCalibration(const YamlContext& r, const YAML::Node& root, const Scenario& s) {
  if (s.subject.preset.empty() && !s.subject.random_seed)
    r.Fail("subject", "emg_calibration needs subject.preset or subject.random_seed (the anthropometric "
                      "models of Table 7 take the subject's weight and segment lengths)");
  if (!s.human.emg) r.Fail("human.emg", "emg_calibration needs the EMG amplifier (human.emg: true)");
  if (root["protocol"])
    r.Fail("protocol", "not used with emg_calibration (it sets the trials itself: MVC, isometric, gait)");
  if (root["fixed_joints"])
    r.Fail("fixed_joints", "not used with emg_calibration, expected emg_calibration.hip_pose / knee_pose");
  if (s.human.contractions < 2)
    r.Fail("human.contractions", "emg_calibration needs at least 2 (flexion and extension per joint)");
  if (s.human.behaviour != "relaxed")
    r.Fail("human.behaviour", "emg_calibration sets the behaviour of each trial itself; leave it out");
}

}  // namespace

Scenario ParseScenarioYaml(const std::string& text, const std::string& source) {
  const YamlContext r{source};
  const YAML::Node root = ParseYaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario file");
  if (!root.IsMap()) throw InputError(source + ": expected a YAML mapping at the top level");
  YamlCheckKeys(r, root, "", {"name", "description", "seed", "subject", "human", "device", "fixed_joints", "protocol",
                    "hardware", "controller", "faults", "logs", "checks", "hal", "emg_calibration", "plant"});
  Scenario s;
  s.source = source;
  ParseHeader(r, root, s);
  ParseSubject(r, root, s);
  if (root["human"]) ParseHuman(r, root["human"], s);
  if (root["hal"]) ParseHal(r, root["hal"], s);
  if (root["emg_calibration"]) ParseEmgCalibration(r, root["emg_calibration"], s);
  if (root["fixed_joints"]) ParseFixedJoints(r, root["fixed_joints"], s);
  if (root["protocol"]) ParseProtocol(r, root["protocol"], s);
  if (root["hardware"]) ParseHardware(r, root["hardware"], s);
  if (root["controller"]) ParseController(r, root["controller"], s);
  if (root["faults"] && !root["faults"].IsNull()) ParseFaults(r, root["faults"], s);
  if (root["logs"]) ParseLogs(r, root["logs"], s);
  if (root["checks"] && !root["checks"].IsNull()) ParseChecks(r, root["checks"], s);
  if (s.emg_calibration) CheckEmgCalibration(r, root, s);
  if (root["plant"]) ParsePlant(r, root["plant"], s);
  // The HAL-3 runner takes its metrics after hal.settle: a run no longer than that has none (and a
  // sweep's criteria would divide by zero).
  if (s.device == Device::kHal3 && !(s.protocol.duration > s.hal.settle))
    r.Fail("protocol.duration", NumberText(s.protocol.duration) + " s leaves no time after hal.settle (" +
                                    NumberText(s.hal.settle) + " s) for the metrics, expected a run longer than hal.settle");
  CheckScenarioMetrics(s);  // a check the run cannot judge is refused now, not after the run
  return s;
}

Scenario ReadScenario(const std::string& path) {
  return ParseScenarioYaml(ReadYamlText(path, "scenario"), path);
}

}  // namespace exotwin
