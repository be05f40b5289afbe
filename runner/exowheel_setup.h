// Set-up of an EXOwheel trial (runner/exowheel_runner.cc) from its scenario: the controller's
// reference and configuration, the joint modules' hardware, the subject's muscles and behaviour.
#pragma once
#include <memory>

#include <Eigen/Core>

#include "controller/controller_config.h"
#include "controller/exo_controller.h"
#include "controller/trajectory.h"
#include "hwsim/joint_module.h"
#include "model/lumped_params.h"
#include "runner/scenario.h"
#include "sim/muscles.h"
#include "sim/plant_effects.h"

namespace exotwin {

// The reference of the scenario's protocol and fixed_joints (what the controller file says): gait
// (Winter, knee shifted by -3 deg to the exoskeleton's stop), the identification excitation, a hold,
// or a recorded motion (trajectory: file: the OpenSim motion file at protocol.path, read here and
// handed to the controller as samples). Throws InputError naming the motion file and line for a bad one.
controller::ReferenceSpec ReferenceOf(const Scenario& s);

// The reference of trial `trial` (0-based): controller::BuildReference of ReferenceOf(s), faded in
// over protocol.ramp s.
std::shared_ptr<const controller::LegTrajectory> BuildTrajectory(const Scenario& s, int trial);

// The ExoController of the scenario: its gains, rate and limits, and as its feed-forward model the
// exoskeleton of `truth` plus, with a subject, the De Leva anthropometric estimate (what a rig knows
// before identifying the user).
controller::ExoControllerConfig ControllerConfig(const Scenario& s, const LegParams& truth);

// The controller file of the scenario (ControllerConfig is ExoConfigOf of it): what the deployable
// controller needs to run the scenario's trials (`exotwin serve` writes it as OUT/controller.yaml).
controller::ControllerFile ControllerFileOf(const Scenario& s, const LegParams& truth);

// The joint module of joint j (0 hip, 1 knee) with the scenario's hardware (sensors, encoder, driver).
hwsim::JointModuleSpec JointModuleSpecOf(const HardwareSpec& hw, int j);
// The same with the torque-sensor effects of the scenario's plant block at that joint (DESIGN.md
// "Effects": sensor_offset, sensor_gain in the order listed, folded into the sensor's offset and
// gain; sensor_delay as a delay of the torque sample, a whole number of sample_s). Throws InputError
// naming `source` for a delay that is not a whole number of samples.
hwsim::JointModuleSpec JointModuleSpecOf(const HardwareSpec& hw, int j, const std::vector<SensorEffect>& sensor,
                                         double sample_s, const std::string& source);

// The subject's muscles: ground truth alpha, beta, gamma drawn from human.muscle_seed (Tables 6-7),
// with co-contraction stiffening the joints about the trial's posture (the held start pose `start`
// (rad) of isometric trials, the gait's mean posture in exaggerated gait).
MuscleParams SubjectMuscles(const Scenario& s, const Eigen::Vector2d& start);

// The subject's behaviour in the trial (human.behaviour; relaxed unless the scenario says otherwise),
// with muscles `mp`; an exaggerated gait amplifies `trajectory`; isometric programmes seeded by `seed`
// unless human.programme_seed is set.
std::unique_ptr<Behaviour> BuildBehaviour(const Scenario& s, const MuscleParams& mp,
                                          const std::shared_ptr<const controller::LegTrajectory>& trajectory,
                                          uint64_t seed);

}  // namespace exotwin
