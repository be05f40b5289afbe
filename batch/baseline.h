// Baselines of the controller-regression gate: scenarios/baselines/<scenario name>.json holds the
// deterministic metrics of one scenario run and optional per-metric tolerance overrides:
//   {"scenario": "gait_2kmh", "source": "gait_2kmh.yaml", "seed": 1,
//    "metrics": {"tracking_rms_hip_deg": 0.21, ...},
//    "tolerance": {"tracking_rms_hip_deg": {"abs": 0.02, "rel": 0.05}}}
// `tolerance` is optional; entries may give abs, rel or both (a missing one is 0).
#pragma once
#include <cstdint>
#include <map>
#include <string>

#include "batch/metric_tolerance.h"

namespace exotwin {

struct Baseline {
  std::string scenario, source;
  uint64_t seed = 0;
  std::map<std::string, double> metrics;
  std::map<std::string, Tolerance> tolerance;  // overrides of DefaultTolerance
};

// Reads a baseline file. Throws InputError naming the file and the field on bad content.
Baseline ReadBaseline(const std::string& path);

// Writes a baseline file atomically (metrics at full precision, keys sorted).
void WriteBaseline(const Baseline& b, const std::string& path);

}  // namespace exotwin
