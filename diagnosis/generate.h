// `exotwin generate`: measured data from a truth twin that carries hidden effects drawn by a seed,
// for testing the discrepancy loop (and users' own pipelines) against a known answer.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "formats/measured_data.h"
#include "core/rng.h"
#include "core/units.h"
#include "model/lumped_params.h"

namespace exotwin {

struct GenerateOptions {
  uint64_t seed = 1;
  int effects = 1;                      // number of hidden effects (distinct names), 0..3
  std::vector<std::string> allowed;     // effect names the draw may use; empty = all of DESIGN.md
  std::string joint;                    // "hip" / "knee" forces the joint; empty = drawn
  double duration = 60.0;               // s, > 2
  double rate = 1000.0;                 // Hz, 100 .. 10000
  // Terms beyond the table hidden besides the drawn effects (generate --term; DESIGN.md "Terms beyond
  // the table"): name "term", joint, value, expr and stage as a model file's. They draw nothing from the
  // seed (the same seed gives the same trajectory and noise with or without them).
  std::vector<Effect> terms;
};

struct GeneratedData {
  MeasuredData data;  // t, q_*, tau_* (sensor), emg_* columns, in this order
  LegParams truth;    // the model file's params plus the hidden effects
  double torque_noise = 0;  // sensor noise standard deviation, N m
};

// generate's joint ranges (rad): the trajectory stays inside them, and so does a drawn stiffness's rest
// angle; a one-joint device's (HAL's convention, 0 hanging, + extension): the seated swing's -0.3 ..
// +1.0 rad of the HAL-3 scenarios, widened a little.
constexpr double kGenerateJointLo[2] = {5 * kRadPerDeg, -70 * kRadPerDeg};
constexpr double kGenerateJointHi[2] = {40 * kRadPerDeg, -5 * kRadPerDeg};
constexpr double kGenerateOneJointLo = -0.4, kGenerateOneJointHi = 1.2;

// Names of DESIGN.md's effect families generate may hide (those with FitFamily::draw), in its table
// order (GenerateMeasured also draws from families added to the registry since).
const std::vector<std::string>& AllEffectNames();

// Draws one effect of `name` at `joint` (0 hip, 1 knee) with a magnitude in its realistic range:
// coulomb 0.3-1.5 N m, viscous 0.3-2 N m s/rad, inertia +-(0.05-0.3) kg m^2, gravity +-(0.05-0.3)
// kg m, stiffness 3-15 N m/rad, backlash 0.3-1.7 deg, straps 150-800 N m/rad at the knee and
// 800-3000 at the hip (resonance at least twice the motion's frequency, DESIGN.md's range), ripple
// 0.2-1 N m at 2-8 cycles/rad, offset +-(0.2-2) N m, gain +-(2-10) %, delay 5-30 ms, muscle
// weights 3-10 N m/V. `one_joint`: the stiffness's q0 in the one-joint range (-0.4 .. 1.2 rad).
Effect DrawEffect(Rng& rng, const std::string& name, int joint, bool one_joint = false);

// Generates the record: trajectory of three harmonics (0.3-1.5 Hz) per joint inside hip 5..40 deg,
// knee -70..-5 deg (a one-joint model, params.one_joint: the hip held at 0, the joint inside
// -0.4 .. 1.2 rad, every effect at it, a one-joint record); EMG on GMAX, RF, VM, ST, GAS (white noise modulated by slow random activations);
// truth torque by the MuJoCo twin (analytic derivatives) plus ApplyEffects; encoder quantization
// 2^19 counts/rev; torque sensor noise 0.02-0.04 N m (drawn) and 0.005 N m resolution.
// Throws InputError for options out of range or params without a realization, and for a term whose
// expr is outside the grammar (naming --term, the position in it), whose joint is not hip or knee (knee
// in a one-joint model), whose value is not finite or whose stage is not link, sensor or empty.
GeneratedData GenerateMeasured(const LegParams& params, const GenerateOptions& opt);

// Writes the generated record as a measured-data CSV (comments name the seed, not the truth).
void WriteGeneratedCsv(const GeneratedData& g, const std::string& path, uint64_t seed);

}  // namespace exotwin
