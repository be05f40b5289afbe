#include "batch/metric_tolerance.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace exotwin {
namespace {

bool StartsWith(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }
bool EndsWith(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(s.size() - p.size(), p.size(), p) == 0;
}

}  // namespace

double Tolerance::For(double baseline) const { return std::max(abs, rel * std::abs(baseline)); }

Tolerance DefaultTolerance(const std::string& m) {
  if (StartsWith(m, "tracking_")) return {0.01, 0.03};
  if (StartsWith(m, "torque_")) return {0.2, 0.02};
  if (EndsWith(m, "_time_s") || EndsWith(m, "_reaction_s")) return {0.002, 0};
  if (m == "bus_load_pct") return {0.5, 0};
  if (m == "frames") return {0, 0.005};
  if (m == "frames_dropped" || m == "error_frames") return {2, 0.05};
  if (m == "samples" || m == "safe_state_entered" || m == "final_state") return {0, 0};
  return {1e-9, 1e-3};
}

Better PreferredDirection(const std::string& m) {
  if (StartsWith(m, "tracking_") || m == "torque_max_after_safe" || m == "torque_max_50ms_after_fault" ||
      m == "safe_reaction_s" || m == "frames_dropped" || m == "error_frames")
    return Better::kLower;
  return Better::kNone;
}

const char* VerdictName(Verdict v) {
  switch (v) {
    case Verdict::kSame: return "same";
    case Verdict::kWithin: return "ok";
    case Verdict::kImproved: return "improved";
    case Verdict::kRegressed: return "REGRESSED";
    case Verdict::kChanged: return "CHANGED";
    case Verdict::kNew: return "new";
    case Verdict::kMissing: return "MISSING";
  }
  return "?";
}

bool IsFailure(Verdict v) {
  return v == Verdict::kRegressed || v == Verdict::kChanged || v == Verdict::kMissing;
}

std::vector<MetricDelta> CompareMetrics(const std::map<std::string, double>& baseline,
                                        const std::map<std::string, double>& now,
                                        const std::map<std::string, Tolerance>& overrides) {
  std::set<std::string> names;
  for (const auto& kv : baseline) names.insert(kv.first);
  for (const auto& kv : now) names.insert(kv.first);
  std::vector<MetricDelta> out;
  for (const std::string& name : names) {
    MetricDelta d;
    d.metric = name;
    auto b = baseline.find(name), n = now.find(name);
    d.baseline = b != baseline.end() ? b->second : std::nan("");
    d.now = n != now.end() ? n->second : std::nan("");
    auto o = overrides.find(name);
    const Tolerance tol = o != overrides.end() ? o->second : DefaultTolerance(name);
    d.tolerance = tol.For(d.baseline);
    d.delta = d.now - d.baseline;
    if (b == baseline.end()) d.verdict = Verdict::kNew;
    else if (n == now.end()) d.verdict = Verdict::kMissing;
    else if (d.now == d.baseline || (std::isnan(d.now) && std::isnan(d.baseline))) d.verdict = Verdict::kSame;
    else if (std::isnan(d.now) || std::isnan(d.baseline)) d.verdict = Verdict::kChanged;
    else if (std::abs(d.delta) <= d.tolerance) d.verdict = Verdict::kWithin;
    else if (PreferredDirection(name) == Better::kLower) d.verdict = d.delta < 0 ? Verdict::kImproved : Verdict::kRegressed;
    else d.verdict = Verdict::kChanged;
    out.push_back(d);
  }
  return out;
}

}  // namespace exotwin
