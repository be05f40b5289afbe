// Set-up of a HAL-3 run (runner/hal_runner.cc) from its scenario: the plant's inertials, the
// operator's muscles and the controller's HalLoop configuration.
#pragma once
#include "controller/hal_loop.h"
#include "runner/scenario.h"
#include "sim/hal3_plant.h"
#include "sim/muscles.h"

namespace exotwin {

constexpr int kHalExtChannel = 1, kHalFlexChannel = 3;  // EMG channels of HAL's two sensor units: VM, ST
constexpr double kHalRmsWindow = 0.1;  // s, T of HKS05 eq. 1, controller and calibration alike

// The plant of a preset or population subject (Hal3ParamsForSubject), HAL defaults without one.
// Throws InputError for a subject.params file (device hal3 takes no MODEL.yaml).
Hal3PlantParams Hal3PlantParamsOf(const Scenario& s);

// The operator's muscles: ground truth drawn from human.muscle_seed, plus the relaxed knee's own
// passive viscoelasticity about the hanging leg (our choice: K0 = 1.5 N m/rad, D0 = 0.3 N m s/rad, of
// the order of pendulum-test values for a relaxed knee; Hayashi's D, K include it).
MuscleParams OperatorMuscles(const Scenario& s);

// The HalLoop of the scenario (hal.mode, rate, torque limit 60 N m at most) on plant `pp`, with the
// HKS05 eq. 2 EMG calibration `emg` and the virtual viscosity B_v (N m s/rad) of Lee & Sankai's tau_c.
controller::HalLoopConfig HalLoopConfigOf(const Scenario& s, const Hal3PlantParams& pp,
                                          const controller::HalEmgCoefficients& emg, double B_v);

}  // namespace exotwin
