// diagnosis.json, extended.yaml and the report of a Diagnosis (DESIGN.md "diagnose").
#include <nlohmann/json.hpp>


#include <cstring>

#include "formats/csv_table.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_report.h"
#include "formats/model_file.h"
#include "formats/number_text.h"
#include "core/error.h"
#include "core/output_path.h"

namespace exotwin {

std::string AliasText(const EffectAlias& a) {
  std::string s;
  for (const Effect& e : a.effects)
    s += (s.empty() ? "" : " + ") + e.name + (e.axis.empty() ? "" : "." + e.axis) + " (" + e.joint + ") = " +
         NumberText(e.value, 4) + " " + e.unit + (e.expr.empty() ? "" : " * " + e.expr);
  return s + " (reaches " + NumberText(a.reach_pct, 4) + " % of its fit, leaves it " + NumberText(a.left_pct, 2) + " %)" +
         (a.plausible ? "" : " [outside its range]");
}

std::string DiagnosisJson(const Diagnosis& d) {
  using nlohmann::json;
  json j;
  j["fit"] = DiagnoseFitName(d.fit);
  j["effects"] = json::array();
  for (const auto& e : d.effects) {
    json x = {{"name", e.effect.name}, {"joint", e.effect.joint}, {"value", e.effect.value},
              {"unit", e.effect.unit}, {"ci95", {e.ci_lo, e.ci_hi}}, {"explained_pct", e.explained_pct}};
    if (std::isfinite(e.spread_sd))
      x["spread"] = {{"sd", e.spread_sd}, {"segments_left_out", {e.spread_lo, e.spread_hi}}};
    if (!e.effect.axis.empty()) x["axis"] = e.effect.axis;
    if (!e.effect.expr.empty()) {  // a term beyond the table (DESIGN.md "Terms beyond the table")
      x["expr"] = e.effect.expr;
      if (!e.effect.stage.empty()) x["stage"] = e.effect.stage;
      x["formula"] = std::string(e.effect.stage == "sensor" ? "tau_S" : "tau_R") + "(" + e.effect.joint +
                     ") += " + nlohmann::json(e.effect.value).dump() + " * " + e.effect.expr;
    }
    for (const auto& f : e.effect.fields) {
      if (f.first.rfind("w_", 0) == 0) x["weights"][f.first.substr(2)] = f.second;
      else x[f.first] = f.second;
    }
    x["aliases"] = json::array();
    for (const EffectAlias& a : e.aliases) {
      json ja = {{"reach_pct", a.reach_pct}, {"left_pct", a.left_pct}, {"plausible", a.plausible}, {"effects", json::array()}};
      for (const Effect& f : a.effects) {
        json jf = {{"name", f.name}, {"joint", f.joint}, {"value", f.value}, {"unit", f.unit}};
        if (!f.axis.empty()) jf["axis"] = f.axis;
        if (!f.expr.empty()) jf["expr"] = f.expr, jf["stage"] = f.stage;
        ja["effects"].push_back(jf);
      }
      x["aliases"].push_back(ja);
    }
    j["effects"].push_back(x);
  }
  j["unexplained"] = json::array();
  for (const auto& u : d.unexplained)
    j["unexplained"].push_back({{"joint", u.joint}, {"rms", u.rms},
                                {"signature", {{"dominant_hz", u.dominant_hz}, {"corr_angle", u.corr_q},
                                               {"corr_velocity", u.corr_qd}, {"corr_acceleration", u.corr_qdd},
                                               {"corr_time", u.corr_t}}},
                                {"hint", u.hint}});
  const char* names[2] = {"hip", "knee"};
  const int k0 = d.extended.one_joint ? 1 : 0;  // a one-joint device reports its joint only
  if (d.extended.one_joint) j["one_joint"] = true;
  auto score = [](const JointScore& s) {
    return json{{"rmse_before", s.rmse_before}, {"rmse_after", s.rmse_after}, {"gain_pct", s.gain_pct}};
  };
  for (int k = k0; k < 2; ++k) j["joints"][names[k]] = score(d.joints[k]);
  j["validation"] = {{"method", d.method}, {"holdout_fraction", d.holdout_fraction},
                     {"leave_one_record_out", d.leave_one_out}};
  j["noise"] = {{"knee", d.noise[1]}, {"autocorrelation_rows", d.tau_eff}};
  if (!d.extended.one_joint) j["noise"]["hip"] = d.noise[0];
  j["collinear"] = d.collinear;
  j["cutoff"] = {{"hz", d.cutoff.from_columns ? 0.0 : d.cutoff.hz},
                 {"source", d.cutoff.from_columns ? "measured qd/qdd columns" : "butterworth"},
                 {"why", d.cutoff.why},
                 {"candidates_hz", d.cutoff.candidates_hz},
                 {"heldout_rmse_knee", d.cutoff.heldout_rmse[1]}};
  if (!d.extended.one_joint) j["cutoff"]["heldout_rmse_hip"] = d.cutoff.heldout_rmse[0];
  j["selection"] = d.selection;
  j["term_search"] = d.term_search;
  j["implausible"] = d.implausible;
  j["not_identifiable"] = d.not_identifiable;
  j["records"] = json::array();
  for (const auto& r : d.records) {
    json x = {{"source", r.source}, {"samples", r.samples}};
    for (int k = k0; k < 2; ++k) {
      x["split"][names[k]] = score(r.split[k]);
      if (d.leave_one_out) x["left_out"][names[k]] = score(r.left_out[k]);
      x["ceiling"][names[k]] = score(r.ceiling[k]);
      x["ceiling_null"][names[k]] = score(r.ceiling_null[k]);
    }
    j["records"].push_back(x);
  }
  if (d.leave_one_out)
    for (int k = k0; k < 2; ++k) j["left_out"][names[k]] = score(d.left_out[k]);
  // Forward simulation (DESIGN.md "Diagnosis output and method": simulation), angles in rad.
  const SimulationScores& S = d.simulation;
  auto sim = [](const JointScore& s) {
    return json{{"rmse_before_rad", s.rmse_before}, {"rmse_after_rad", s.rmse_after}, {"gain_pct", s.gain_pct}};
  };
  json js = {{"done", S.done}, {"method", S.note}, {"horizon_s", S.horizon_s}, {"cutoff_hz", S.cutoff_hz}};
  if (S.done) {
    for (int k = k0; k < 2; ++k) js["joints"][names[k]] = sim(S.split[k]);
    if (d.leave_one_out)
      for (int k = k0; k < 2; ++k) js["left_out"][names[k]] = sim(S.left_out[k]);
    js["records"] = json::array();
    for (const auto& r : d.records) {
      json x = {{"source", r.source}, {"windows_split", r.sim_split_windows}};
      for (int k = k0; k < 2; ++k) x["split"][names[k]] = sim(r.sim_split[k]);
      if (d.leave_one_out) {
        x["windows_left_out"] = r.sim_left_out_windows;
        for (int k = k0; k < 2; ++k) x["left_out"][names[k]] = sim(r.sim_left_out[k]);
      }
      js["records"].push_back(x);
    }
    if (S.torque_fit_done) {
      json t = {{"not_carried", S.torque_fit_not_carried}};
      for (int k = k0; k < 2; ++k) t["joints"][names[k]] = sim(S.torque_fit_split[k]);
      if (d.leave_one_out)
        for (int k = k0; k < 2; ++k) t["left_out"][names[k]] = sim(S.torque_fit_left_out[k]);
      if (!S.torque_fit_why.empty()) t["why_worse"] = S.torque_fit_why;
      js["torque_fit"] = t;
    }
  }
  j["simulation"] = js;
  // DESIGN.md "Terms beyond the table": the residual tests of the table's and the final model, and the
  // final model's ceiling.
  auto verdict = [](const JointCompleteness& c) {
    json x = {{"complete", c.complete}, {"assessed", c.assessed}, {"rows", c.rows}, {"step_rows", c.step},
              {"alpha", c.alpha}, {"material_floor", c.floor}, {"rms", c.rms},
              {"tests", json::object()}};
    for (const CompletenessTest& t : c.tests)
      x["tests"][t.name] = {{"statistic", t.statistic}, {"threshold", t.threshold}, {"p_value", t.p_value},
                             {"size", t.size}, {"pass", t.pass}};
    return x;
  };
  for (int k = k0; k < 2; ++k) {
    j["completeness"]["table"][names[k]] = verdict(d.table_model.completeness[k]);
    j["completeness"]["final"][names[k]] = verdict(d.final_model.completeness[k]);
    const JointCeiling& c = d.final_model.ceiling[k];
    j["ceiling"][names[k]] = {{"done", c.done}, {"named_pct", c.named_pct}, {"black_box_pct", c.black_box_pct},
                              {"given_rms", c.given_rms}, {"train_rows", c.train_rows}, {"heldout_rows", c.heldout_rows}};
  }
  if (d.fit == DiagnoseFit::kMotion) {  // what the torque fit would have named, and what it alone names
    auto effect = [](const Effect& e) {
      json x = {{"name", e.name}, {"joint", e.joint}, {"value", e.value}, {"unit", e.unit}};
      if (!e.axis.empty()) x["axis"] = e.axis;
      return x;
    };
    j["torque_fit"] = json::array();
    for (const auto& e : d.torque_named) {
      json x = effect(e.effect);
      x["ci95"] = {e.ci_lo, e.ci_hi};
      j["torque_fit"].push_back(x);
    }
    j["torque_only"] = json::array();
    for (const auto& t : d.torque_only) {
      json x = effect(t.effect);
      x["simulated"] = t.simulated;
      if (!t.simulated) x["why"] = t.why;
      if (t.simulated)
        for (int k = k0; k < 2; ++k) {
          x["heldout_change_pct"][names[k]] = t.heldout_change_pct[k];
          if (std::isfinite(t.in_torque_twin_pct[k])) x["in_torque_twin_pct"][names[k]] = t.in_torque_twin_pct[k];
        }
      j["torque_only"].push_back(x);
    }
  }
  return j.dump(2) + "\n";
}

void WriteDiagnosis(const Diagnosis& d, const std::string& dir, const std::string& params_path,
                    const std::string& measured_path) {
  CreateOutputFolder(dir);
  WriteFileAtomic(dir + "/diagnosis.json", DiagnosisJson(d));
  std::string header = "exotwin diagnose: " + params_path + " extended with the effects found in " +
                       measured_path;
  for (const auto& e : d.effects)
    header += "\n" + e.effect.name + " (" + e.effect.joint + "): 95 % interval " +
              std::to_string(e.ci_lo) + " .. " + std::to_string(e.ci_hi) + " " + e.effect.unit;
  WriteFileAtomic(dir + "/extended.yaml", ModelToYaml(d.extended, header));
  WriteFileAtomic(dir + "/report.html", DiagnosisReportHtml(d, params_path, measured_path));
}

}  // namespace exotwin
