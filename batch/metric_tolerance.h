// Tolerances of the controller-regression gate: how far a scenario metric may move from its
// baseline, per metric kind (overridable per baseline file), and the verdict of a comparison.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace exotwin {

// A metric may move by max(abs, rel * |baseline|) (same unit as the metric).
struct Tolerance {
  double abs = 0;  // metric unit
  double rel = 0;  // fraction of |baseline|
  double For(double baseline) const;  // the allowed |now - baseline|
};

// Which way a metric gets better; kNone: any move beyond tolerance is a change to review.
enum class Better { kNone, kLower };

// Default tolerance by metric kind (name pattern): tracking errors 0.01 deg or 3 %, torques 0.2 N m
// or 2 %, times 2 ms, bus load 0.5 %, frame counts 0.5 %, counts and states exact.
Tolerance DefaultTolerance(const std::string& metric);
Better PreferredDirection(const std::string& metric);

enum class Verdict {
  kSame,       // bit-identical
  kWithin,     // moved, within tolerance
  kImproved,   // beyond tolerance in the better direction (not a failure; --update to accept)
  kRegressed,  // beyond tolerance in the worse direction
  kChanged,    // beyond tolerance, metric without a better direction
  kNew,        // not in the baseline (not a failure)
  kMissing,    // in the baseline, not produced any more
};
const char* VerdictName(Verdict v);  // "same", "ok", "improved", "REGRESSED", "CHANGED", "new", "MISSING"
bool IsFailure(Verdict v);

struct MetricDelta {
  std::string metric;
  double baseline = 0, now = 0, delta = 0, tolerance = 0;  // metric unit; NaN where absent
  Verdict verdict = Verdict::kSame;
};

// Compares every metric of `now` and `baseline` (sorted by name); `overrides` replaces the default
// tolerance of the metrics it names. NaN equals NaN.
std::vector<MetricDelta> CompareMetrics(const std::map<std::string, double>& baseline,
                                        const std::map<std::string, double>& now,
                                        const std::map<std::string, Tolerance>& overrides = {});

}  // namespace exotwin
