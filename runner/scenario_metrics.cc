#include "runner/scenario_metrics.h"

#include "core/error.h"

namespace exotwin {
namespace {

// '*' matches any text (also none); everything else itself. Iterative (greedy with one backtrack
// point, linear in practice): a metric name is user text of any length.
bool Matches(const std::string& pattern, const std::string& name) {
  size_t p = 0, n = 0, star = std::string::npos, resume = 0;
  while (n < name.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = n;
    } else if (p < pattern.size() && pattern[p] == name[n]) {
      ++p, ++n;
    } else if (star != std::string::npos) {
      p = star + 1;
      n = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

// runner/exowheel_runner.cc's result metrics.
const char* const kExowheel[] = {
    "samples", "tracking_rms_hip_deg", "tracking_rms_knee_deg", "tracking_max_hip_deg", "tracking_max_knee_deg",
    "torque_max_hip", "torque_max_knee", "torque_rms_hip", "torque_rms_knee", "bus_load_pct", "frames",
    "frames_dropped", "error_frames", "fault_time_s", "safe_state_time_s", "safe_reaction_s",
    "torque_max_after_safe", "torque_max_50ms_after_fault", "safe_state_entered", "final_state"};

// runner/hal_runner.cc's: every run's, assist mode's RLS, a sweep's.
const char* const kHal[] = {
    "samples", "runs", "emg_ext_up_V", "emg_ext_down_V", "emg_flex_up_V", "emg_flex_down_V", "emg_ext_up_rect_V",
    "strain_up_Nm", "strain_down_Nm", "mu_ext_up_Nm", "J_tau_m", "J_e", "J_f", "th_max", "th_min",
    "tracking_rms_rad", "plant_I", "plant_mgl", "emg_a_ext", "emg_a_flex", "emg_b_ext", "emg_b_flex",
    "emg_baseline_ext_V", "emg_baseline_flex_V", "bus_load_pct", "frames_dropped", "emg_gaps"};
const char* const kHalAssist[] = {"rls_D_mean", "rls_K_mean", "truth_D_mean", "truth_K_mean", "truth_D_timemean",
                                  "truth_K_timemean", "rls_D_err_pct", "rls_K_err_pct", "rls_K_err_pct_of_Kprime",
                                  "rls_I_hat"};
const char* const kHalSweep[] = {"J_tau_m@*", "J_me@*", "J_mf@*", "sweep_argmin_viscosity", "sweep_min_J_tau_m",
                                 "sweep_rise_low_pct", "sweep_rise_high_pct", "sweep_argmin_J_me_viscosity",
                                 "sweep_paper_optimum"};

// runner/emg_calibration_protocol.cc's (per muscle, direction, joint and parameter set).
const char* const kEmgCalibration[] = {"samples", "safe_state_entered", "torque_max_hip", "torque_max_knee",
                                       "mvc_*_V", "iso_*", "alpha_*", "dyn_*", "gait_tracking_rms_hip_deg",
                                       "gait_tracking_rms_knee_deg", "r2_margin_*", "tau_M_*"};

const char* KindName(const Scenario& s) {
  if (s.device == Device::kHal3) return "a hal3 scenario";
  if (s.emg_calibration) return "an emg_calibration scenario";
  return "an EXOwheel scenario";
}

}  // namespace

std::vector<std::string> ScenarioMetricPatterns(const Scenario& s) {
  std::vector<std::string> p;
  auto add = [&p](const auto& list) { p.insert(p.end(), std::begin(list), std::end(list)); };
  if (s.device == Device::kHal3) {
    add(kHal);
    if (s.hal.mode == "assist") add(kHalAssist);
    if (!s.hal.sweep_viscosity.empty()) add(kHalSweep);
  } else if (s.emg_calibration) {
    add(kEmgCalibration);
    if (s.emg_calibration->subjects > 1) {  // means over the subjects, their spread, each subject's
      const std::vector<std::string> base(p);
      for (const std::string& b : base) p.push_back(b + "_sd"), p.push_back(b + "_subjects_positive");
      for (const std::string& b : base) p.push_back("subject_S*." + b);
      p.push_back("subjects");
    }
  } else {
    add(kExowheel);
  }
  p.push_back("wall_time_s");
  p.push_back("link_*");
  return p;
}

bool IsScenarioMetric(const Scenario& s, const std::string& metric) {
  for (const std::string& p : ScenarioMetricPatterns(s))
    if (Matches(p, metric)) return true;
  return false;
}

void CheckScenarioMetrics(const Scenario& s) {
  for (size_t i = 0; i < s.checks.size(); ++i) {
    if (IsScenarioMetric(s, s.checks[i].metric)) continue;
    std::string list;
    for (const std::string& p : ScenarioMetricPatterns(s)) list += (list.empty() ? "" : ", ") + p;
    throw InputError(s.source + ": checks[" + std::to_string(i) + "].metric: unknown metric '" + s.checks[i].metric +
                     "' for " + KindName(s) + " (expected one of: " + list + ")");
  }
}

}  // namespace exotwin
