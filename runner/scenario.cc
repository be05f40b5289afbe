#include "runner/scenario.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "model/input_error.h"
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

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw InputError(source_ + ": " + key + ": " + what);
  }

  static std::string Line(const YAML::Node& n) {
    return n.Mark().line >= 0 ? " (line " + std::to_string(n.Mark().line + 1) + ")" : "";
  }

  void Keys(const YAML::Node& n, const std::string& key, const std::set<std::string>& allowed) const {
    if (!n.IsMap()) Fail(key, "expected a mapping" + Line(n));
    std::set<std::string> seen;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar())
        Fail(key.empty() ? "(top level)" : key, "expected plain keys, found a non-scalar key" + Line(kv.first));
      const std::string k = kv.first.Scalar();
      if (!seen.insert(k).second) Fail(key.empty() ? k : key + "." + k, "duplicated key" + Line(kv.first));
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(key.empty() ? k : key + "." + k, "unknown key" + Line(kv.first) + ", expected one of: " + list);
      }
    }
  }

  double Num(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    if (!n.IsScalar()) Fail(key, "expected a number" + Line(n));
    double v;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      Fail(key, "'" + n.Scalar() + "' is not a number" + Line(n));
    }
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream os;
      os << "value " << n.Scalar() << " out of range, expected " << lo << " .. " << hi << Line(n);
      Fail(key, os.str());
    }
    return v;
  }

  std::string Str(const YAML::Node& n, const std::string& key, const std::set<std::string>& allowed = {}) const {
    if (!n.IsScalar()) Fail(key, "expected a string" + Line(n));
    const std::string s = n.Scalar();
    if (!allowed.empty() && !allowed.count(s)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      Fail(key, "'" + s + "' is not one of: " + list + Line(n));
    }
    return s;
  }

  bool Bool(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) Fail(key, "expected true or false" + Line(n));
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      Fail(key, "'" + n.Scalar() + "' is not true/false" + Line(n));
    }
  }

  void Pair(const YAML::Node& n, const std::string& key, double out[2], double lo, double hi) const {
    if (!n.IsSequence() || n.size() != 2) Fail(key, "expected [hip, knee]" + Line(n));
    out[0] = Num(n[0], key + "[0]", lo, hi);
    out[1] = Num(n[1], key + "[1]", lo, hi);
  }

 private:
  std::string source_;
};

const std::set<std::string> kFaultTypes = {"sensor_stuck", "sensor_stale", "encoder_glitch", "frame_drop",
                                           "frame_late",   "bus_off",      "command_loss",   "nan_measurement"};

void ParseHal(const Reader& r, const YAML::Node& n, Scenario& s) {
  if (s.device != Device::kHal3) r.Fail("hal", "only allowed with device: hal3");
  r.Keys(n, "hal", {"mode", "alpha_mu", "alpha_zeta", "virtual_viscosity", "sweep_viscosity", "swing_freq",
                    "cc_up", "cc_down", "settle", "rls_gravity_in_input", "rls_known_inertia",
                    "operator_delay", "cc_synergy", "rls_friction_in_input", "calibration_levels",
                    "calibration_hi", "calibration_rest"});
  HalSpec& h = s.hal;
  if (n["mode"]) h.mode = r.Str(n["mode"], "hal.mode", {"none", "impedance", "assist"});
  if (n["alpha_mu"]) h.alpha_mu = r.Num(n["alpha_mu"], "hal.alpha_mu", 0, 5);
  if (n["alpha_zeta"]) h.alpha_zeta = r.Num(n["alpha_zeta"], "hal.alpha_zeta", 0, 5);
  if (n["virtual_viscosity"]) h.virtual_viscosity = r.Num(n["virtual_viscosity"], "hal.virtual_viscosity", -5, 20);
  if (n["sweep_viscosity"]) {
    const YAML::Node v = n["sweep_viscosity"];
    if (!v.IsSequence() || v.size() < 2 || v.size() > 50)
      r.Fail("hal.sweep_viscosity", "expected a list of 2..50 viscosities (N m s/rad)" + Reader::Line(v));
    for (size_t i = 0; i < v.size(); ++i)
      h.sweep_viscosity.push_back(r.Num(v[i], "hal.sweep_viscosity[" + std::to_string(i) + "]", -5, 20));
  }
  if (n["swing_freq"]) h.swing_freq = r.Num(n["swing_freq"], "hal.swing_freq", 0.1, 2);
  if (n["cc_up"]) h.cc_up = r.Num(n["cc_up"], "hal.cc_up", 0, 1);
  if (n["cc_down"]) h.cc_down = r.Num(n["cc_down"], "hal.cc_down", 0, 1);
  if (n["settle"]) h.settle = r.Num(n["settle"], "hal.settle", 0, 3600);
  if (n["operator_delay"]) h.operator_delay = r.Num(n["operator_delay"], "hal.operator_delay", 0, 0.3);
  if (n["rls_gravity_in_input"]) h.rls_gravity_in_input = r.Bool(n["rls_gravity_in_input"], "hal.rls_gravity_in_input");
  if (n["calibration_levels"]) h.calibration_levels = static_cast<int>(r.Num(n["calibration_levels"], "hal.calibration_levels", 2, 50));
  if (n["calibration_hi"]) h.calibration_hi = r.Num(n["calibration_hi"], "hal.calibration_hi", 0.05, 1);
  if (n["calibration_rest"]) h.calibration_rest = r.Num(n["calibration_rest"], "hal.calibration_rest", 0.5, 60);
  if (n["rls_friction_in_input"])
    h.rls_friction_in_input = r.Bool(n["rls_friction_in_input"], "hal.rls_friction_in_input");
  if (n["cc_synergy"]) h.cc_synergy = r.Bool(n["cc_synergy"], "hal.cc_synergy");
  if (n["rls_known_inertia"]) h.rls_known_inertia = r.Bool(n["rls_known_inertia"], "hal.rls_known_inertia");
}

void ParseEmgCalibration(const Reader& r, const YAML::Node& n, Scenario& s) {
  if (s.device != Device::kExowheel) r.Fail("emg_calibration", "only allowed with device: exowheel");
  r.Keys(n, "emg_calibration", {"dynamic", "mvc_trials", "hip_pose", "knee_pose", "strides", "subjects", "fit_window"});
  EmgCalibrationSpec c;
  if (n["dynamic"]) c.dynamic = r.Bool(n["dynamic"], "emg_calibration.dynamic");
  if (n["mvc_trials"]) c.mvc_trials = static_cast<int>(r.Num(n["mvc_trials"], "emg_calibration.mvc_trials", 1, 10));
  if (n["hip_pose"]) r.Pair(n["hip_pose"], "emg_calibration.hip_pose", c.hip_pose, -2.5, 2.5);
  if (n["knee_pose"]) r.Pair(n["knee_pose"], "emg_calibration.knee_pose", c.knee_pose, -2.5, 2.5);
  if (n["strides"]) c.strides = static_cast<int>(r.Num(n["strides"], "emg_calibration.strides", 1, 100));
  if (n["subjects"]) c.subjects = static_cast<int>(r.Num(n["subjects"], "emg_calibration.subjects", 1, 10));
  if (n["fit_window"]) c.fit_window = r.Str(n["fit_window"], "emg_calibration.fit_window", {"active", "trial"});
  s.emg_calibration = c;
}

}  // namespace

Scenario ParseScenarioYaml(const std::string& text, const std::string& source) {
  Reader r(source);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": line " + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario file");
  if (!root.IsMap()) throw InputError(source + ": expected a YAML mapping at the top level");
  r.Keys(root, "", {"name", "description", "seed", "subject", "human", "device", "fixed_joints", "protocol",
                    "hardware", "controller", "faults", "logs", "checks", "hal", "emg_calibration"});
  Scenario s;
  s.source = source;
  if (!root["name"]) r.Fail("name", "missing, expected the scenario's name");
  s.name = r.Str(root["name"], "name");
  if (root["seed"]) s.seed = static_cast<uint64_t>(r.Num(root["seed"], "seed", 0, 1e15));

  if (!root["device"]) r.Fail("device", "missing, expected exowheel, exowheel_exo_only or hal3");
  const std::string dev = r.Str(root["device"], "device", {"exowheel", "exowheel_exo_only", "hal3"});
  s.device = dev == "exowheel" ? Device::kExowheel
                               : (dev == "hal3" ? Device::kHal3 : Device::kExowheelExoOnly);

  if (root["subject"]) {
    const YAML::Node n = root["subject"];
    r.Keys(n, "subject", {"preset", "random_seed", "params", "passive"});
    const int given = !!n["preset"] + !!n["random_seed"] + !!n["params"];
    if (given != 1) r.Fail("subject", "expected exactly one of preset, random_seed, params");
    if (n["preset"]) {
      const std::vector<std::string> presets = PresetNames();
      s.subject.preset = r.Str(n["preset"], "subject.preset", {presets.begin(), presets.end()});
    }
    if (n["random_seed"])
      s.subject.random_seed = static_cast<uint64_t>(r.Num(n["random_seed"], "subject.random_seed", 0, 1e15));
    if (n["params"]) s.subject.params_file = r.Str(n["params"], "subject.params");
    if (n["passive"])
      s.subject.passive = r.Str(n["passive"], "subject.passive", {"none", "riener1999"}) == "none"
                              ? PassiveModel::kNone
                              : PassiveModel::kRiener1999;
  } else if (s.device != Device::kExowheelExoOnly) {
    r.Fail("subject", "missing, expected {preset: S1} or {random_seed: N} or {params: FILE}");
  }

  if (root["human"]) {
    const YAML::Node n = root["human"];
    r.Keys(n, "human", {"behaviour", "active_from", "gain", "contractions", "levels", "cocontraction",
                        "programme_seed", "emg", "muscle_seed", "outward_gate"});
    HumanSpec& h = s.human;
    if (n["behaviour"])
      h.behaviour = r.Str(n["behaviour"], "human.behaviour",
                          {"relaxed", "exaggerated_gait", "isometric_hip", "isometric_knee"});
    if (n["active_from"]) h.active_from = r.Num(n["active_from"], "human.active_from", 0, 3600);
    if (n["gain"]) h.gain = r.Num(n["gain"], "human.gain", 0.5, 3);
    if (n["outward_gate"]) h.outward_gate = r.Num(n["outward_gate"], "human.outward_gate", 0, 100);
    if (n["contractions"]) h.contractions = static_cast<int>(r.Num(n["contractions"], "human.contractions", 1, 100));
    if (n["levels"]) {
      const YAML::Node v = n["levels"];
      if (!v.IsSequence() || v.size() != 2) r.Fail("human.levels", "expected [lo, hi] (fraction of MVC)" + Reader::Line(v));
      h.levels[0] = r.Num(v[0], "human.levels[0]", 0, 1);
      h.levels[1] = r.Num(v[1], "human.levels[1]", 0, 1);
      if (!(h.levels[0] <= h.levels[1])) r.Fail("human.levels", "expected [lo, hi] with lo <= hi (fraction of MVC)");
    }
    if (n["cocontraction"]) h.cocontraction = r.Num(n["cocontraction"], "human.cocontraction", 0, 1);
    if (n["programme_seed"])
      h.programme_seed = static_cast<uint64_t>(r.Num(n["programme_seed"], "human.programme_seed", 0, 1e15));
    if (n["emg"]) h.emg = r.Bool(n["emg"], "human.emg");
    if (n["muscle_seed"]) h.muscle_seed = static_cast<uint64_t>(r.Num(n["muscle_seed"], "human.muscle_seed", 0, 1e15));
  }

  if (root["hal"]) ParseHal(r, root["hal"], s);
  if (root["emg_calibration"]) ParseEmgCalibration(r, root["emg_calibration"], s);

  if (root["fixed_joints"]) {
    const YAML::Node n = root["fixed_joints"];
    r.Keys(n, "fixed_joints", {"hip", "knee"});
    for (const auto& kv : n) {
      const std::string j = kv.first.as<std::string>();
      s.fixed_joints[j] = r.Num(kv.second, "fixed_joints." + j, -2.5, 2.5);
    }
  }

  if (root["protocol"]) {
    const YAML::Node n = root["protocol"];
    r.Keys(n, "protocol", {"trajectory", "duration", "trials", "stride_period", "moving_joint",
                           "excitation_seed", "ramp"});
    ProtocolSpec& p = s.protocol;
    if (n["trajectory"]) {
      const std::string t = r.Str(n["trajectory"], "protocol.trajectory", {"gait", "excitation", "hold"});
      p.trajectory = t == "gait" ? TrajectoryKind::kGait
                                 : (t == "excitation" ? TrajectoryKind::kExcitation : TrajectoryKind::kHold);
    }
    if (n["duration"]) p.duration = r.Num(n["duration"], "protocol.duration", 0.01, 3600);
    if (n["trials"]) p.trials = static_cast<int>(r.Num(n["trials"], "protocol.trials", 1, 100));
    if (n["stride_period"]) p.stride_period = r.Num(n["stride_period"], "protocol.stride_period", 0.5, 10);
    if (n["moving_joint"]) p.moving_joint = r.Str(n["moving_joint"], "protocol.moving_joint", {"hip", "knee", "both"});
    if (n["excitation_seed"])
      p.excitation_seed = static_cast<uint64_t>(r.Num(n["excitation_seed"], "protocol.excitation_seed", 0, 1e15));
    if (n["ramp"]) p.ramp = r.Num(n["ramp"], "protocol.ramp", 0, 60);
  }

  if (root["hardware"]) {
    const YAML::Node n = root["hardware"];
    r.Keys(n, "hardware", {"can_bitrate", "can_latency", "can_jitter", "can_drop_rate", "torque_sensor_noise",
                           "torque_sensor_offset", "encoder_bits", "motor_lag", "torque_limit", "watchdog",
                           "torque_sensor_skew"});
    HardwareSpec& h = s.hardware;
    if (n["can_bitrate"]) h.can_bitrate = r.Num(n["can_bitrate"], "hardware.can_bitrate", 10e3, 1e6);
    if (n["can_latency"]) h.can_latency = r.Num(n["can_latency"], "hardware.can_latency", 0, 0.1);
    if (n["can_jitter"]) h.can_jitter = r.Num(n["can_jitter"], "hardware.can_jitter", 0, 0.01);
    if (n["can_drop_rate"]) h.can_drop_rate = r.Num(n["can_drop_rate"], "hardware.can_drop_rate", 0, 1);
    if (n["torque_sensor_noise"])
      h.torque_sensor_noise = r.Num(n["torque_sensor_noise"], "hardware.torque_sensor_noise", 0, 10);
    if (n["torque_sensor_offset"])
      r.Pair(n["torque_sensor_offset"], "hardware.torque_sensor_offset", h.torque_sensor_offset, -120, 120);
    if (n["encoder_bits"]) h.encoder_bits = static_cast<int>(r.Num(n["encoder_bits"], "hardware.encoder_bits", 8, 24));
    if (n["motor_lag"]) h.motor_lag = r.Num(n["motor_lag"], "hardware.motor_lag", 0, 0.05);
    if (n["torque_limit"]) h.torque_limit = r.Num(n["torque_limit"], "hardware.torque_limit", 1, 500);
    if (n["watchdog"]) h.watchdog = r.Num(n["watchdog"], "hardware.watchdog", 0.002, 1);
    if (n["torque_sensor_skew"]) {
      const double k = r.Num(n["torque_sensor_skew"], "hardware.torque_sensor_skew", -100, 100);
      if (k != std::round(k))
        r.Fail("hardware.torque_sensor_skew", "expected a whole number of samples, found " + n["torque_sensor_skew"].Scalar() +
                                                     Reader::Line(n["torque_sensor_skew"]));
      h.torque_sensor_skew = static_cast<int>(k);
    }
  }

  if (root["controller"]) {
    const YAML::Node n = root["controller"];
    r.Keys(n, "controller", {"rate_hz", "kp", "kd", "feedforward", "torque_limit"});
    ControllerSpec& c = s.controller;
    if (n["rate_hz"]) c.rate_hz = r.Num(n["rate_hz"], "controller.rate_hz", 100, 10000);
    if (n["kp"]) r.Pair(n["kp"], "controller.kp", c.kp, 0, 1e5);
    if (n["kd"]) r.Pair(n["kd"], "controller.kd", c.kd, 0, 1e4);
    if (n["feedforward"]) c.feedforward = r.Bool(n["feedforward"], "controller.feedforward");
    if (n["torque_limit"]) c.torque_limit = r.Num(n["torque_limit"], "controller.torque_limit", 1, 500);
  }

  if (root["faults"] && !root["faults"].IsNull()) {
    if (!root["faults"].IsSequence()) r.Fail("faults", "expected a list");
    int i = 0;
    for (const auto& n : root["faults"]) {
      const std::string key = "faults[" + std::to_string(i++) + "]";
      r.Keys(n, key, {"type", "joint", "at", "duration", "value"});
      FaultSpec f;
      if (!n["type"]) r.Fail(key + ".type", "missing");
      f.type = r.Str(n["type"], key + ".type", kFaultTypes);
      if (n["joint"]) f.joint = r.Str(n["joint"], key + ".joint", {"hip", "knee", "all"});
      if (n["at"]) f.at = r.Num(n["at"], key + ".at", 0, 3600);
      if (n["duration"]) f.duration = r.Num(n["duration"], key + ".duration", 0, 3600);
      if (n["value"]) f.value = r.Num(n["value"], key + ".value", -1e6, 1e6);
      s.faults.push_back(f);
    }
  }

  if (root["logs"]) {
    const YAML::Node n = root["logs"];
    r.Keys(n, "logs", {"measured_csv", "rate_hz"});
    if (n["measured_csv"]) s.log_measured_csv = r.Bool(n["measured_csv"], "logs.measured_csv");
    if (n["rate_hz"]) s.log_rate_hz = r.Num(n["rate_hz"], "logs.rate_hz", 1, 10000);
  }

  if (root["checks"] && !root["checks"].IsNull()) {
    if (!root["checks"].IsSequence()) r.Fail("checks", "expected a list");
    int i = 0;
    for (const auto& n : root["checks"]) {
      const std::string key = "checks[" + std::to_string(i++) + "]";
      r.Keys(n, key, {"name", "metric", "max", "min"});
      CheckSpec c;
      if (!n["metric"]) r.Fail(key + ".metric", "missing, expected a metric name");
      c.metric = r.Str(n["metric"], key + ".metric");
      c.name = n["name"] ? r.Str(n["name"], key + ".name") : c.metric;
      if (!!n["max"] == !!n["min"]) r.Fail(key, "expected exactly one of max, min");
      if (n["max"]) { c.limit = r.Num(n["max"], key + ".max", -1e12, 1e12); c.op = "<="; }
      else { c.limit = r.Num(n["min"], key + ".min", -1e12, 1e12); c.op = ">="; }
      s.checks.push_back(c);
    }
  }
  if (s.emg_calibration) {
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
  return s;
}

Scenario ReadScenario(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (text.find('\0') != std::string::npos)
    throw InputError(path + ": binary data (NUL byte), expected a YAML text file");
  return ParseScenarioYaml(text, path);
}

}  // namespace exotwin
