// Set-up of a HAL-3 run (runner/hal_runner.cc) from its scenario: the plant's inertials, the
// operator's muscles and the controller's HalLoop configuration.
#pragma once
#include <cstdint>

#include "controller/controller_config.h"
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

// The runs of a HAL-3 scenario: one per hal.sweep_viscosity value, else protocol.trials.
int HalRuns(const Scenario& s);
// The virtual viscosity B_v (N m s/rad) of run `run` (0-based): the swept value, else hal.virtual_viscosity.
double HalRunViscosity(const Scenario& s, int run);
// The seed of run `run` for the run's seed `seed`: a sweep keeps the same seed for every value (common
// random numbers: only B_v changes), trials differ.
uint64_t HalRunSeed(const Scenario& s, uint64_t seed, int run);
// The operator's EMG calibration (HKS05 eq. 2, CalibrateHalEmg) of a run with seed `run_seed`.
controller::HalEmgCoefficients HalRunCalibration(const Scenario& s, const MuscleParams& operator_muscles,
                                                 uint64_t run_seed);
// The controller file of a HAL-3 loop configuration (DESIGN.md "Controller file", `hal:`): the
// scenario's controller part and drivers (min(60, hardware.torque_limit) N m, the HAL-3 actuator).
controller::ControllerFile HalControllerFile(const Scenario& s, const controller::HalLoopConfig& loop);
// The controller file of run `run` (0-based) of the scenario run with seed `seed`.
controller::ControllerFile HalControllerFileOf(const Scenario& s, uint64_t seed, int run);

}  // namespace exotwin
