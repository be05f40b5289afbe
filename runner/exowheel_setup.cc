// Set-up of an EXOwheel trial from its scenario: see exowheel_setup.h.
#include "runner/exowheel_setup.h"

#include <algorithm>
#include <cmath>

#include "formats/number_text.h"
#include "formats/opensim_kinematics.h"
#include "core/error.h"
#include "runner/runner.h"
#include "sim/anthropometry.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

using controller::LegTrajectory;
using controller::TabulatedTrajectory;

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

// Mean posture of the gait pattern (Winter, fitted): about 5 deg hip, -25 deg knee (rad).
const Eigen::Vector2d kGaitMeanPosture(0.09, -0.45);

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

// trajectory: file. The OpenSim motion file's hip and knee (formats/opensim_kinematics.h), its first
// sample at t = 0; a non-uniform record is interpolated linearly onto a uniform grid at its median
// step (as formats/measured_data.h DeriveKinematics does), then handed to the controller as samples
// (controller::ReferenceKind::kSamples, played by TabulatedTrajectory).
void RecordedSamples(const ProtocolSpec& p, controller::ReferenceSpec* r) {
  const MeasuredData m = ReadOpenSimKinematics(p.path, p.side);
  const double dt = MedianStep(m.t());
  const double span = m.t().back() - m.t().front();
  const size_t n = static_cast<size_t>(std::floor(span / dt + 1e-9)) + 1;
  std::vector<double> grid(n);
  for (size_t i = 0; i < n; ++i) grid[i] = m.t().front() + static_cast<double>(i) * dt;
  if (!(p.cutoff < 0.5 / dt))
    throw InputError(p.path + ": sampled at " + NumberText(1.0 / dt) + " Hz; protocol.cutoff " + NumberText(p.cutoff) +
                     " Hz must lie below its Nyquist frequency " + NumberText(0.5 / dt) + " Hz");
  r->kind = controller::ReferenceKind::kSamples;
  r->sample_dt = dt;
  r->sample_hip = Interpolate(m.t(), m.q_hip(), grid);
  r->sample_knee = Interpolate(m.t(), m.q_knee(), grid);
  r->sample_loop = p.extend != "hold";
  r->sample_cutoff = p.cutoff;
}

}  // namespace

controller::ReferenceSpec ReferenceOf(const Scenario& s) {
  const ProtocolSpec& p = s.protocol;
  controller::ReferenceSpec r;
  r.kind = p.trajectory == TrajectoryKind::kGait         ? controller::ReferenceKind::kGait
           : p.trajectory == TrajectoryKind::kExcitation ? controller::ReferenceKind::kExcitation
                                                         : controller::ReferenceKind::kHold;
  r.stride_period = p.stride_period;
  r.moving_joint = p.moving_joint;
  r.excitation_seed = p.excitation_seed;
  r.ramp = p.ramp;
  if (auto it = s.fixed_joints.find("hip"); it != s.fixed_joints.end()) r.hold_hip = it->second;
  if (auto it = s.fixed_joints.find("knee"); it != s.fixed_joints.end()) r.hold_knee = it->second;
  if (p.trajectory == TrajectoryKind::kFile) RecordedSamples(p, &r);
  return r;
}

std::shared_ptr<const LegTrajectory> BuildTrajectory(const Scenario& s, int trial) {
  return controller::BuildReference(ReferenceOf(s), trial);
}

controller::ControllerFile ControllerFileOf(const Scenario& s, const LegParams& truth) {
  controller::ControllerFile f;
  f.source = s.source;
  f.controller = s.controller;
  f.driver_limit = s.hardware.torque_limit;
  f.model = ControllerModel(s, truth);
  f.reference = ReferenceOf(s);
  f.trials = s.protocol.trials;
  return f;
}

controller::ExoControllerConfig ControllerConfig(const Scenario& s, const LegParams& truth) {
  return controller::ExoConfigOf(ControllerFileOf(s, truth));
}

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
    // velocity that bursts at the knee's 1-3 Hz swing harmonics (measured: knee R^2 of HJ15 eq. 28 falls
    // from 0.93 to 0.24 with kd = 15), unlike a person exaggerating a slow 2 km/h gait, whose effort
    // follows the posture. kd = 0: the exaggeration is an amplitude intent, kp (gain - 1)(q* - mean).
    TrackingGains gains;
    gains.kd.setZero();
    return std::make_unique<ExaggeratedGait>(mp, base, kGaitMeanPosture, h.gain, h.active_from, 0.02, gains,
                                             h.outward_gate);
  }
  return std::make_unique<RelaxedBehaviour>();
}

hwsim::JointModuleSpec JointModuleSpecOf(const HardwareSpec& hw, int j) {
  hwsim::JointModuleSpec ms;
  ms.joint = static_cast<msg::Joint>(j);
  ms.torque_sensor.offset = hw.torque_sensor_offset[j];
  ms.torque_sensor.repeatability_fs = hw.torque_sensor_noise / ms.torque_sensor.range;
  ms.encoder.bits = hw.encoder_bits;
  ms.driver.lag = hw.motor_lag;
  ms.driver.limit = hw.torque_limit;
  ms.driver.watchdog = hw.watchdog;
  ms.torque_sensor_skew = hw.torque_sensor_skew;
  return ms;
}

hwsim::JointModuleSpec JointModuleSpecOf(const HardwareSpec& hw, int j, const std::vector<SensorEffect>& sensor,
                                         double sample_s, const std::string& source) {
  hwsim::JointModuleSpec ms = JointModuleSpecOf(hw, j);
  if (sensor.empty()) return ms;
  // The reading as an affine map a tau + b of the true torque, the effects applied in order; then
  // (tau + offset) (1 + gain) with offset = b / a + the sensor's own, gain = a - 1.
  double a = 1, b = 0;
  for (const SensorEffect& e : sensor) {
    if (!e.expr.empty())
      throw InputError(source + ": a sensor-stage term (\"" + e.expr + "\") at the " + (j == 0 ? "hip" : "knee") +
                       ": a scenario's joint modules apply the affine sensor effects and the delay only; carried at "
                       "the link stage, or in replay");
    const EffectFamily* f = FindFamily(e.name);
    if (f->affine) {
      f->affine(e.value, &a, &b);
    } else {
      const double k = e.value / sample_s;
      if (std::abs(k - std::round(k)) > 1e-9)
        throw InputError(source + ": " + e.name + " " + std::to_string(e.value) + " s of the " +
                         (j == 0 ? "hip" : "knee") + ": expected a whole number of the joint module's " +
                         std::to_string(sample_s) + " s samples");
      ms.torque_sensor_skew += static_cast<int>(std::lround(k));
    }
  }
  ms.torque_sensor.offset += b / a;
  ms.torque_sensor.gain = a - 1;
  return ms;
}

MuscleParams SubjectMuscles(const Scenario& s, const Eigen::Vector2d& start) {
  MuscleParams mp = DrawMuscleParams(s.human.muscle_seed);
  mp.q_rest = CoContractionPosture(s, mp, start);
  return mp;
}

}  // namespace exotwin
