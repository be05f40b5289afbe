#include "runner/runner.h"

#include "runner/emg_calibration_protocol.h"
#include "runner/hal_runner.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include <unistd.h>

#include "analysis/csv_table.h"
#include "analysis/model_file.h"
#include "controller/exo_controller.h"
#include "core/error.h"
#include "core/units.h"
#include "hwsim/joint_module.h"
#include "hwsim/virtual_can_bus.h"
#include "protocol/candump.h"
#include "render/video_renderer.h"
#include "dsp/butterworth.h"
#include "model/leg_dynamics.h"
#include "hwsim/emg_amplifier.h"
#include "sim/anthropometry.h"
#include "sim/muscles.h"
#include "sim/synthetic_emg.h"
#include "sim/plant.h"
#include "sim/subjects.h"

namespace exotwin {

bool RunResult::all_passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.passed; });
}

std::optional<Subject> ScenarioSubject(const Scenario& s) {
  if (!s.subject.preset.empty()) return PresetSubject(s.subject.preset);
  if (s.subject.random_seed) return DrawSubject(*s.subject.random_seed, 0);
  return std::nullopt;
}

ContractionProgramme IsometricProgrammeOf(const HumanSpec& h, uint64_t run_seed) {
  return IsometricProgramme(h.behaviour == "isometric_hip" ? 0 : 1, h.contractions, h.levels[0], h.levels[1],
                            h.cocontraction, h.programme_seed ? *h.programme_seed : run_seed);
}

LegParams ResolveSubject(const Scenario& s) {
  LegParams p;
  if (!s.subject.params_file.empty()) {
    p = ReadModelFile(s.subject.params_file);
  } else if (!s.subject.preset.empty()) {
    p = SubjectLegParams(PresetSubject(s.subject.preset));
  } else if (s.subject.random_seed) {
    p = SubjectLegParams(DrawSubject(*s.subject.random_seed, 0));
  } else {
    // Exo-only scenario without a subject: the mean exoskeleton of Table 3 at L1 = 0.41 m.
    p.L1 = 0.41;
    p.exo = {3.01, 0.74, 3.85, 1.73, 0.14, 0.18};
  }
  if (s.device == Device::kExowheelExoOnly) {
    p.human.reset();
    p.passive = PassiveModel::kNone;
  } else if (s.subject.params_file.empty()) {
    p.passive = s.subject.passive;
  }
  return p;
}

namespace {

using controller::FadeInTrajectory;
using controller::GaitSpec;
using controller::GaitTrajectory;
using controller::HarmonicTrajectory;
using controller::HoldTrajectory;
using controller::JointTrajectory;
using controller::JointwiseTrajectory;
using controller::LegTrajectory;

// The reference of a trial: gait, excitation of the moving joint(s) with the others held, or hold.
std::shared_ptr<const LegTrajectory> BuildTrajectory(const Scenario& s, int trial) {
  const ProtocolSpec& p = s.protocol;
  auto held = [&](const char* j, double dflt) {
    auto it = s.fixed_joints.find(j);
    return it != s.fixed_joints.end() ? it->second : dflt;
  };
  std::shared_ptr<const LegTrajectory> inner;
  switch (p.trajectory) {
    case TrajectoryKind::kGait: {
      GaitSpec g;
      g.stride_period_s = p.stride_period;
      // Winter's knee reaches +2 deg (hyperextension) in stance; the exoskeleton stops at 0, so
      // the pattern is shifted by -3 deg at the knee.
      g.knee_offset = -3.0 / kDegPerRad;  // the double nearest -3 pi / 180 (-3 * kRadPerDeg is 1 ulp off)
      inner = std::make_shared<GaitTrajectory>(GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath(), g));
      break;
    }
    case TrajectoryKind::kExcitation: {
      const uint64_t seed = p.excitation_seed * 1000003ull + static_cast<uint64_t>(trial);
      std::shared_ptr<const JointTrajectory> hip, knee;
      if (p.moving_joint == "hip" || p.moving_joint == "both")
        hip = std::make_shared<HarmonicTrajectory>(
            HarmonicTrajectory::Design(controller::ExcitationSpec::PaperHip(), seed));
      else
        hip = std::make_shared<HoldTrajectory>(held("hip", M_PI / 2));
      if (p.moving_joint == "knee" || p.moving_joint == "both")
        knee = std::make_shared<HarmonicTrajectory>(
            HarmonicTrajectory::Design(controller::ExcitationSpec::PaperKnee(), seed + 7));
      else
        knee = std::make_shared<HoldTrajectory>(held("knee", -M_PI / 2));
      inner = std::make_shared<JointwiseTrajectory>(hip, knee);
      break;
    }
    case TrajectoryKind::kHold:
      inner = std::make_shared<JointwiseTrajectory>(std::make_shared<HoldTrajectory>(held("hip", 0.3)),
                                                    std::make_shared<HoldTrajectory>(held("knee", -0.5)));
      break;
  }
  if (p.ramp > 0) inner = std::make_shared<FadeInTrajectory>(inner, p.ramp);
  return inner;
}

// The controller's model for the feed-forward: the exoskeleton (known from its own identification)
// plus, with a subject, the De Leva anthropometric estimate from the subject's weight and lengths:
// what a rig knows before identifying the user.
LegParams ControllerModel(const Scenario& s, const LegParams& truth) {
  LegParams m;
  m.L1 = truth.L1;
  m.exo = truth.exo;
  if (truth.human) {
    double weight = 68.0, L2 = 0.53;
    if (const std::optional<Subject> sub = ScenarioSubject(s)) {
      weight = sub->weight;
      L2 = sub->L2;
    }
    m.human = Table4AnthropometricLumped(AnthropometricModel::kDeLeva, weight, truth.L1, L2);
    m.passive = PassiveModel::kRiener1999;
  }
  return m;
}

controller::ExoControllerConfig ControllerConfig(const Scenario& s, const LegParams& truth) {
  controller::ExoControllerConfig c;
  c.rate_hz = s.controller.rate_hz;
  c.hip = {s.controller.kp[0], s.controller.kd[0], s.controller.torque_limit};
  c.knee = {s.controller.kp[1], s.controller.kd[1], s.controller.torque_limit};
  c.feedforward = s.controller.feedforward;
  c.model = ControllerModel(s, truth);
  c.estimator.sample_rate_hz = s.controller.rate_hz;
  c.safety = controller::SafetyConfig::Default();
  for (auto* lim : {&c.safety.hip, &c.safety.knee}) {
    lim->tau_sensor_max = std::min(115.0, s.hardware.torque_limit);
    lim->tau_cmd_max = s.controller.torque_limit + 1e-6;
    lim->qd_max = 8.0;  // rad/s (460 deg/s): gait at 2 km/h peaks near 200 deg/s
  }
  return c;
}

// Mean posture of the gait pattern (Winter, fitted): about 5 deg hip, -25 deg knee (rad).
const Eigen::Vector2d kGaitMeanPosture(0.09, -0.45);

// The subject's behaviour for the trial (relaxed unless the scenario's human block says otherwise).
std::unique_ptr<Behaviour> BuildBehaviour(const Scenario& s, const MuscleParams& mp,
                                          const std::shared_ptr<const LegTrajectory>& trajectory,
                                          uint64_t seed) {
  const HumanSpec& h = s.human;
  if (h.behaviour == "isometric_hip" || h.behaviour == "isometric_knee")
    return std::make_unique<ContractionProgramme>(IsometricProgrammeOf(h, seed));
  if (h.behaviour == "exaggerated_gait") {
    IntendedMotion base = [trajectory](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
      controller::JointSetpoint a, b;
      trajectory->Sample(t, &a, &b);
      q = {a.q, b.q};
      qd = {a.qd, b.qd};
      qdd = {a.qdd, b.qdd};
    };
    // The exoskeleton imposes the motion (PD 600/400 N m/rad), so the subject's damping term of the
    // tracking law (TrackingGains::kd, sized to stabilise the FREE limb with 55 ms of loop delay) has
    // nothing to stabilise; kept, it adds kd (gain - 1) qd of the pattern: a drive in phase with the
    // velocity that bursts at the knee's 1-3 Hz swing harmonics (measured: knee R^2 of eq. 28 falls
    // from 0.93 to 0.24 with kd = 15), unlike a person exaggerating a slow 2 km/h gait, whose effort
    // follows the posture. kd = 0: the exaggeration is an amplitude intent, kp (gain - 1)(q* - mean).
    TrackingGains gains;
    gains.kd.setZero();
    return std::make_unique<ExaggeratedGait>(mp, base, kGaitMeanPosture, h.gain, h.active_from, 0.02, gains,
                                             h.outward_gate);
  }
  return std::make_unique<RelaxedBehaviour>();
}

// The posture the subject's co-contraction stiffens the joints about (MuscleParams::q_rest, rad).
// Co-contraction raises the joint stiffness about the current equilibrium (Hogan 1984, IEEE TAC
// 29(8)); the seated-hanging default of sim/muscles (Hayashi's K theta for the HAL knee swing) would
// make a standing subject's co-contraction pull the knee towards -90 deg: a torque of -K (q - q_rest),
// about -0.33 S N m in gait (S the co-contracted torque), that no EMG model sees. Isometric trials:
// the held start pose; exaggerated gait: the pattern's mean posture (as tests/sim/muscles_test.cc).
Eigen::Vector2d CoContractionPosture(const Scenario& s, const MuscleParams& mp, const Eigen::Vector2d& start) {
  if (s.human.behaviour == "exaggerated_gait") return kGaitMeanPosture;
  if (s.human.behaviour == "isometric_hip" || s.human.behaviour == "isometric_knee") return start;
  return mp.q_rest;
}

struct FaultSwitch {
  FaultSpec spec;
  bool active = false;
};

// Applies the scenario's faults that are active at time t to the modules and the bus.
void ApplyFaults(std::vector<FaultSwitch>& faults, double t, hwsim::JointModule* modules[2],
                 hwsim::VirtualCanBus& bus, hwsim::VirtualCanBus::Endpoint* controller_node,
                 const HardwareSpec& hw, std::vector<std::string>* events) {
  for (FaultSwitch& f : faults) {
    const bool on = t >= f.spec.at && (f.spec.duration <= 0 || t < f.spec.at + f.spec.duration);
    if (on == f.active) continue;
    f.active = on;
    char buf[160];
    std::snprintf(buf, sizeof(buf), "t=%.3f %s %s %s", t, on ? "on" : "off", f.spec.type.c_str(),
                  f.spec.joint.c_str());
    events->push_back(buf);
    for (int j = 0; j < 2; ++j) {
      if (f.spec.joint != "all" && f.spec.joint != (j == 0 ? "hip" : "knee")) continue;
      hwsim::JointModuleFaults& mf = modules[j]->faults();
      if (f.spec.type == "sensor_stuck") mf.sensor_stuck = on;
      if (f.spec.type == "sensor_stale") mf.stale = on;
      if (f.spec.type == "encoder_glitch") mf.encoder_glitch = on;
      if (f.spec.type == "nan_measurement") mf.sensor_nan = on;
      if (f.spec.type == "command_loss") mf.drop_commands = on;
    }
    hwsim::VirtualCanBusConfig& bc = bus.config();
    if (f.spec.type == "frame_drop")
      bc.drop_probability = on ? (f.spec.value > 0 ? f.spec.value : 0.5) : hw.can_drop_rate;
    if (f.spec.type == "frame_late") {
      bc.spike_probability = on ? 1.0 : 0.0;  // every delivery late by `value` s (default 10 ms)
      bc.spike_delay = f.spec.value > 0 ? f.spec.value : 0.01;
    }
    if (f.spec.type == "bus_off") {  // the controller's CAN controller goes bus-off
      if (on) controller_node->ForceBusOff();
      else controller_node->RecoverBusOff();
    }
  }
}

// rad -> deg as (rad * 180) / pi, the rounding the tracking metrics' baselines hold bit for bit
// (rad * kDegPerRad differs in the last bit for about a quarter of the values).
double Deg(double rad) { return rad * 180.0 / M_PI; }

struct Accum {
  double sum2 = 0, max = 0;
  size_t n = 0;
  void Add(double e) {
    sum2 += e * e;
    max = std::max(max, std::abs(e));
    ++n;
  }
  double rms() const { return n ? std::sqrt(sum2 / n) : 0.0; }
};

}  // namespace

RunResult RunScenario(const Scenario& s, const RunOptions& opt) {
  if (s.device == Device::kHal3) return RunHalScenario(s, opt);
  if (s.emg_calibration) return RunEmgCalibrationScenario(s, opt);
  RunResult result;
  result.scenario = s.name;
  result.seed = opt.seed ? *opt.seed : s.seed;
  std::filesystem::create_directories(opt.out_dir);

  const LegParams truth = ResolveSubject(s);
  Plant plant(ShippedModelPath(s.device == Device::kExowheelExoOnly ? "exowheel_exo_only.xml" : "leg_exowheel.xml"));
  plant.SetParams(truth);
  const double dt = plant.timestep();
  const double ctrl_dt = 1.0 / s.controller.rate_hz;
  if (std::abs(ctrl_dt / dt - std::round(ctrl_dt / dt)) > 1e-9 || ctrl_dt < dt - 1e-12)
    throw InputError(s.source + ": controller.rate_hz: expected the physics rate (1000 Hz) divided by an integer");
  const int steps_per_tick = static_cast<int>(std::lround(ctrl_dt / dt));

  std::unique_ptr<CandumpWriter> can_log;
  if (!opt.can_log.empty()) can_log = std::make_unique<CandumpWriter>(opt.can_log, "can0");

  Accum track[2], torque[2];
  double fault_time = -1, safe_time = -1, max_torque_after_safe = 0, bus_load_max = 0;
  double torque_after_fault = 0;  // max |applied torque| from 50 ms after the first fault on
  int final_state = 0;
  uint64_t frames_total = 0, frames_dropped = 0, error_frames = 0;
  size_t samples = 0;
  const auto wall0 = std::chrono::steady_clock::now();
  const bool tty = opt.progress && isatty(2);

  for (int trial = 0; trial < s.protocol.trials; ++trial) {
    const uint64_t seed = result.seed * 7919ull + static_cast<uint64_t>(trial);
    auto trajectory = BuildTrajectory(s, trial);
    controller::JointSetpoint h0, k0;
    trajectory->Sample(0.0, &h0, &k0);

    hwsim::VirtualCanBus bus(BusConfigOf(s.hardware, seed));
    TapToCandump(bus, can_log.get(), trial * (s.protocol.duration + 1.0));  // trials follow each other
    hwsim::VirtualCanBus::Endpoint* ctrl_ep = bus.AddNode("controller", {msg::kIdJointStatusHip, msg::kIdJointStatusKnee, msg::kIdEmgSamples});
    CanBus* emg_ep = bus.AddNode("emg_amplifier", {0x7FF});  // sends only
    CanBus* hip_ep = bus.AddNode("hip_module", {msg::kIdJointCommandHip});
    CanBus* knee_ep = bus.AddNode("knee_module", {msg::kIdJointCommandKnee});

    hwsim::JointModuleSpec ms[2];
    for (int j = 0; j < 2; ++j) {
      ms[j].joint = static_cast<msg::Joint>(j);
      ms[j].torque_sensor.offset = s.hardware.torque_sensor_offset[j];
      ms[j].torque_sensor.repeatability_fs = s.hardware.torque_sensor_noise / ms[j].torque_sensor.range;
      ms[j].encoder.bits = s.hardware.encoder_bits;
      ms[j].driver.lag = s.hardware.motor_lag;
      ms[j].driver.limit = s.hardware.torque_limit;
      ms[j].driver.watchdog = s.hardware.watchdog;
      ms[j].torque_sensor_skew = s.hardware.torque_sensor_skew;
    }
    hwsim::JointModule hip(ms[0], hip_ep, seed + 1), knee(ms[1], knee_ep, seed + 2);
    hwsim::JointModule* modules[2] = {&hip, &knee};
    controller::ExoController ctrl(ControllerConfig(s, truth), trajectory, ctrl_ep);

    // The human: muscles (ground truth alpha, beta, gamma), behaviour, surface EMG -> amplifier.
    const bool human = truth.human.has_value();
    const bool emg_on = human && s.human.emg;
    MuscleParams mp = DrawMuscleParams(s.human.muscle_seed);
    mp.q_rest = CoContractionPosture(s, mp, {h0.q, k0.q});
    MuscleModel muscles(mp, dt);
    std::unique_ptr<Behaviour> behaviour = BuildBehaviour(s, mp, trajectory, seed + 3);
    SyntheticEmg emg(ExowheelSyntheticEmgConfig(), seed + 4);
    hwsim::EmgAmplifier amplifier;
    uint8_t emg_counter = 0;

    std::vector<FaultSwitch> faults;
    for (const FaultSpec& f : s.faults) faults.push_back({f, false});

    const std::string suffix = s.protocol.trials > 1 ? "_trial" + std::to_string(trial + 1) : "";
    std::unique_ptr<CsvStreamWriter> measured, truth_log;
    const std::vector<std::string> comments = {
        "exotwin run " + s.name + " trial " + std::to_string(trial + 1) + " seed " + std::to_string(result.seed),
        "subject truth: L1 " + std::to_string(truth.L1) + (truth.human ? " with human" : " exo only")};
    if (s.log_measured_csv) {
      measured = std::make_unique<CsvStreamWriter>(
          opt.out_dir + "/measured" + suffix + ".csv",
          emg_on ? std::vector<std::string>{"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "cmd_hip", "cmd_knee",
                                            "ref_hip", "ref_knee", "state", "emg_GMAX", "emg_VM", "emg_RF",
                                            "emg_ST", "emg_GAS"}
                 : std::vector<std::string>{"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "cmd_hip", "cmd_knee",
                                            "ref_hip", "ref_knee", "state"},
          comments);
      truth_log = std::make_unique<CsvStreamWriter>(
          opt.out_dir + "/truth" + suffix + ".csv",
          std::vector<std::string>{"t", "q_hip", "q_knee", "qd_hip", "qd_knee", "tau_R_hip", "tau_R_knee",
                                   "tau_M_hip", "tau_M_knee"},
          comments);
      result.files.push_back("measured" + suffix + ".csv");
      result.files.push_back("truth" + suffix + ".csv");
    }

    plant.Reset({h0.q, k0.q}, {h0.qd, k0.qd}, 0.0);
    std::unique_ptr<VideoRenderer> video;
    std::vector<dsp::SosFilter> envelope;
    const controller::ExoControllerConfig ctrl_cfg = ControllerConfig(s, truth);
    if (!opt.video_path.empty() && trial == 0) {
      RenderOptions ro;
      video = std::make_unique<VideoRenderer>(plant.model(), opt.video_path, ro);
      envelope.assign(5, dsp::SosFilter(dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / dt, 3.0)));
    }
    size_t events_seen = result.events.size();
    // Timing of one physics step [t, t + dt] (DESIGN.md "Sampling instant of a joint node"):
    //  - the plant holds tau, the drivers' output at t, over [t, t + dt] (forward zero-order hold);
    //  - the controller ticks at t + dt/2 on the frames sampled at t; its command reaches the driver
    //    before t + dt and shows in the drivers' output at t + dt, which the plant holds over the next
    //    step: one sample (1 ms) from sampling to torque, the transport and computation delay of a
    //    1 kHz CAN loop (sample, send, compute, command, apply at the next period);
    //  - at t + dt each module samples q(t + dt) and the torque held from t + dt, one instant: with
    //    MuJoCo's semi-implicit Euler, qd(t+dt) = qd(t) + dt a(t), q(t+dt) = q(t) + dt qd(t+dt), so
    //    q(t+dt) - 2 q(t) + q(t-dt) = dt^2 a(t) and a(t) follows from the torque held over [t, t + dt]:
    //    the central differences of the logged angles meet inverse dynamics on the logged torque with
    //    no lag.
    double tau[2] = {0, 0};  // the drivers' output at t = 0: no command yet
    const long n_steps = std::lround(s.protocol.duration / dt);
    const long log_every = std::max(1L, std::lround(1.0 / (s.log_rate_hz * dt)));
    const double ctrl_offset = 0.5 * dt;
    double t = 0.0;
    hip.Sample(t, plant.q()[0], tau[0]);
    knee.Sample(t, plant.q()[1], tau[1]);
    for (long k = 0; k < n_steps; ++k) {
      ApplyFaults(faults, t, modules, bus, ctrl_ep, s.hardware, &result.events);
      if (fault_time < 0) {
        for (const auto& f : faults)
          if (f.active) fault_time = t;
      }
      if (k % steps_per_tick == 0) {
        bus.AdvanceTo(t + ctrl_offset);
        ctrl.Tick(t + ctrl_offset);
      }
      Eigen::Vector2d tau_M = Eigen::Vector2d::Zero();
      if (human) {
        muscles.Step(behaviour->Excitation(t, plant.q(), plant.qd()));
        tau_M = muscles.Torques(plant.q(), plant.qd()).total();
      }
      // The torques of this step, for the metrics and truth.csv (row t + dt: the state at t + dt and
      // the actuator and muscle torques held over [t, t + dt], the step that ended there).
      const double applied[2] = {tau[0], tau[1]};
      plant.Step({tau[0], tau[1]}, tau_M);  // the drivers' output at t, held over [t, t + dt]
      bus.AdvanceTo(t + dt * 0.999);
      for (int j = 0; j < 2; ++j) tau[j] = modules[j]->Applied(t + dt, dt);  // the drivers at t + dt
      t = static_cast<double>(k + 1) * dt;  // exact grid (plant.time() accumulates rounding)
      const Eigen::Vector2d q = plant.q();
      hip.Sample(t, q[0], tau[0]);  // one instant: q(t) and the torque held from t
      knee.Sample(t, q[1], tau[1]);
      if (emg_on) {  // the amplifier samples the electrodes at 1 kHz and sends one frame
        const MuscleVec v = emg.Sample(muscles.electrical_activation());
        std::array<double, 5> in{};
        for (int c = 0; c < 5; ++c) in[c] = v[c];
        msg::EmgSamples es;
        const auto out = amplifier.Sample(in);
        for (int c = 0; c < 5; ++c) es.volts[c] = out[c];
        es.counter = emg_counter++ & 0x0F;
        emg_ep->Send(msg::Encode(es));
      }

      const auto& tel = ctrl.telemetry();
      const bool after_ramp = t >= s.protocol.ramp;
      if (tel.safety.state != controller::SafetyState::kRunning && safe_time < 0) safe_time = t;
      for (int j = 0; j < 2; ++j) {
        if (after_ramp && fault_time < 0) track[j].Add(Deg(tel.ref[j].q - q[j]));
        torque[j].Add(applied[j]);
        if (safe_time >= 0 && t > safe_time + 0.05) max_torque_after_safe = std::max(max_torque_after_safe, std::abs(applied[j]));
        // Torque on the faulted joints from 50 ms after the fault on (the damping of a safe state on
        // the other joint is bounded separately by torque_max_after_safe).
        bool faulted_joint = false;
        for (const auto& f : faults)
          faulted_joint |= f.active && (f.spec.joint == "all" || f.spec.joint == (j == 0 ? "hip" : "knee"));
        if (fault_time >= 0 && t > fault_time + 0.05 && faulted_joint)
          torque_after_fault = std::max(torque_after_fault, std::abs(applied[j]));
      }
      if (k % log_every == 0) {
        ++samples;
        if (measured) {
          const double row[] = {t, tel.est[0].q, tel.est[1].q, tel.tau_sensor[0], tel.tau_sensor[1],
                                tel.tau_cmd[0], tel.tau_cmd[1], tel.ref[0].q, tel.ref[1].q,
                                static_cast<double>(tel.safety.state), tel.emg[0], tel.emg[1], tel.emg[2],
                                tel.emg[3], tel.emg[4]};
          measured->Row(row, emg_on ? 15 : 10);
          const Eigen::Vector2d qd = plant.qd();
          const double trow[] = {t, q[0], q[1], qd[0], qd[1], applied[0], applied[1], tau_M[0], tau_M[1]};
          truth_log->Row(trow, 9);
        }
        if (video) {
          OverlaySample os;
          os.t = t;
          os.q_hip = q[0];
          os.q_knee = q[1];
          // The twin's estimate: the controller's own model on its estimated state.
          const Eigen::Vector2d est =
              -ActuatorTorque(ctrl_cfg.model, {tel.est[0].q, tel.est[1].q}, {tel.est[0].qd, tel.est[1].qd},
                              {tel.est[0].qdd, tel.est[1].qdd});
          for (int j = 0; j < 2; ++j) {
            os.tau_meas[j] = std::isfinite(tel.tau_sensor[j]) ? tel.tau_sensor[j] : 0.0;
            os.tau_est[j] = est[j];
          }
          if (emg_on)
            for (int c = 0; c < 5; ++c) os.emg.push_back(envelope[c].Step(std::abs(tel.emg[c])));
          if (result.events.size() > events_seen) os.event = result.events[events_seen++];
          video->AddSample(plant.data(), os);
        }
        if (opt.on_sample) {
          const double qa[2] = {q[0], q[1]};
          opt.on_sample(t, qa, applied);
        }
      }
      if (tty && k % 2000 == 0) {
        const double frac = (trial + static_cast<double>(k) / n_steps) / s.protocol.trials;
        const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        std::fprintf(stderr, "\r%s: trial %d/%d  %5.1f%%  sim %.1f s  eta %.0f s   ", s.name.c_str(), trial + 1,
                     s.protocol.trials, 100 * frac, t, frac > 0 ? el * (1 - frac) / frac : 0.0);
      }
    }
    if (video) {
      video->Finish(t);
      result.files.push_back(opt.video_path);
    }
    final_state = std::max(final_state, static_cast<int>(ctrl.state()));
    const hwsim::CanBusStatistics st = bus.Statistics();
    frames_total += st.frames;
    frames_dropped += st.drops;
    error_frames += st.error_frames;
    bus_load_max = std::max(bus_load_max, st.mean_load_percent);
  }
  if (tty) std::fprintf(stderr, "\n");

  auto& m = result.metrics;
  m["samples"] = static_cast<double>(samples);
  m["tracking_rms_hip_deg"] = track[0].rms();
  m["tracking_rms_knee_deg"] = track[1].rms();
  m["tracking_max_hip_deg"] = track[0].max;
  m["tracking_max_knee_deg"] = track[1].max;
  m["torque_max_hip"] = torque[0].max;
  m["torque_max_knee"] = torque[1].max;
  m["torque_rms_hip"] = torque[0].rms();
  m["torque_rms_knee"] = torque[1].rms();
  m["bus_load_pct"] = bus_load_max;
  m["frames"] = static_cast<double>(frames_total);
  m["frames_dropped"] = static_cast<double>(frames_dropped);
  m["error_frames"] = static_cast<double>(error_frames);
  m["fault_time_s"] = fault_time;
  m["safe_state_time_s"] = safe_time;
  m["safe_reaction_s"] = (fault_time >= 0 && safe_time >= fault_time) ? safe_time - fault_time : -1;
  m["torque_max_after_safe"] = max_torque_after_safe;
  m["torque_max_50ms_after_fault"] = torque_after_fault;
  m["safe_state_entered"] = safe_time >= 0 ? 1.0 : 0.0;
  m["final_state"] = final_state;
  m["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  FinishRun(s, result, opt.out_dir + "/result.json");
  return result;
}

hwsim::VirtualCanBusConfig BusConfigOf(const HardwareSpec& hw, uint64_t seed) {
  hwsim::VirtualCanBusConfig c;
  c.bitrate = hw.can_bitrate;
  c.latency = hw.can_latency;
  c.jitter = hw.can_jitter;
  c.drop_probability = hw.can_drop_rate;
  c.seed = seed;
  return c;
}

void TapToCandump(hwsim::VirtualCanBus& bus, CandumpWriter* log, double epoch) {
  if (!log) return;
  bus.SetTap([log, epoch](const CanFrame& f) {
    CanFrame g = f;
    g.t += epoch;
    log->Write(g);
  });
}

namespace {

// The checks on `m`; a check whose metric is missing is failed with value NaN and named in *unknown.
std::vector<CheckResult> Checks(const Scenario& s, const std::map<std::string, double>& m,
                                std::string* unknown) {
  std::vector<CheckResult> out;
  for (const CheckSpec& c : s.checks) {
    CheckResult r;
    r.name = c.name;
    r.metric = c.metric;
    r.op = c.op;
    r.limit = c.limit;
    auto it = m.find(c.metric);
    if (it == m.end()) {
      if (unknown->empty()) {
        std::string list;
        for (const auto& kv : m) list += (list.empty() ? "" : ", ") + kv.first;
        *unknown = s.source + ": checks: unknown metric '" + c.metric + "', expected one of: " + list;
      }
      r.value = std::numeric_limits<double>::quiet_NaN();
      r.passed = false;
    } else {
      r.value = it->second;
      r.passed = c.op == "<=" ? r.value <= c.limit : r.value >= c.limit;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace

void FinishRun(const Scenario& s, RunResult& result, const std::string& path) {
  std::string unknown;
  result.checks = Checks(s, result.metrics, &unknown);
  WriteResultJson(result, path);
  if (!unknown.empty()) throw InputError(unknown + " (the run's metrics are in " + path + ")");
}

void WriteResultJson(const RunResult& r, const std::string& path) {
  nlohmann::json j;
  j["scenario"] = r.scenario;
  j["seed"] = r.seed;
  j["checks"] = nlohmann::json::array();
  for (const CheckResult& c : r.checks)
    j["checks"].push_back({{"name", c.name}, {"metric", c.metric}, {"op", c.op}, {"passed", c.passed},
                           {"value", c.value}, {"limit", c.limit}});
  j["metrics"] = nlohmann::json::object();
  for (const auto& kv : r.metrics) j["metrics"][kv.first] = kv.second;
  j["files"] = r.files;
  j["events"] = r.events;
  WriteFileAtomic(path, j.dump(2) + "\n");
}

}  // namespace exotwin
