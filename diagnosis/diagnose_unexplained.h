// The structure a twin leaves in a held-out residual (diagnose.h step 6, DESIGN.md "Diagnosis output":
// `unexplained`): one test for both fits, the torque fit's residual torque and the motion fit's
// simulated-angle residual.
#pragma once
#include <cstddef>
#include <optional>
#include <vector>

#include "diagnosis/diagnose.h"

namespace exotwin {

constexpr double kUnexplainedFloorTorque = 0.05;  // N m: no torque residual below it is structure
// rad: no simulated-angle residual below it is structure (a tenth of a degree, the resolution a gait
// analysis reports joint angles at).
constexpr double kUnexplainedFloorAngle = 0.1 * 3.14159265358979323846 / 180;

// A held-out residual of one joint and the motion at its samples: samples [a, b) of each vector (one
// time base), sampled at fs (Hz). A residual of separate windows: their samples in time order, joined.
struct HeldOutResidual {
  const std::vector<double>& t;
  const std::vector<double>& e;  // measured - twin
  const std::vector<double>& q;
  const std::vector<double>& qd;
  const std::vector<double>& qdd;
  size_t a = 0, b = 0;
  double fs = 0;
};

// The structure left in residual r at joint `joint` (0 hip, 1 knee): where its 5 Hz low-pass
// (zero-phase 2nd-order Butterworth, when fs > 12 Hz) has an RMS about its mean above 4 x the white
// noise `noise` low-passed alike (noise sqrt(min(1, 10 / fs))), above `floor`, and above 15 % of
// `rmse_before` (the given twin's held-out error), the structure: its RMS, dominant frequency (a direct
// DFT, 0.05 .. 25 Hz), its Pearson correlations with angle, velocity, acceleration and time, and a hint
// in words (the correlation above 0.3 in magnitude that is largest). nullopt otherwise.
std::optional<UnexplainedStructure> StructureLeft(const HeldOutResidual& r, int joint, double noise, double floor,
                                                  double rmse_before);

}  // namespace exotwin
