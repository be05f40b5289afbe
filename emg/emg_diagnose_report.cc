// diagnosis.json and report.html of the EMG model's discrepancy loop (emg_diagnose.h), in the format
// of `exotwin diagnose` (diagnose_output.cc) where the concepts match.
#include <nlohmann/json.hpp>


#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "formats/csv_table.h"
#include "emg/emg_diagnose.h"
#include "formats/number_text.h"
#include "formats/svg_chart.h"
#include "core/error.h"
#include "core/output_path.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

const char* kJoint[2] = {"hip", "knee"};


std::string Joints(Muscle m) {
  std::string o;
  for (int j = 0; j < 2; ++j)
    if (ActionSign(m, j) != 0) o += std::string(o.empty() ? "" : "+") + kJoint[j];
  return o;
}

// The named causes of the final model in diagnose's effect format.
nlohmann::json Effects(const EmgDiagnosis& d) {
  using nlohmann::json;
  json a = json::array();
  const EmgTorqueModel& m = d.calibration;
  if (m.spec.common_delay != 0) {
    const double v = m.spec.common_delay, se = m.spec.common_delay_se;
    a.push_back({{"name", "electromechanical_delay"}, {"muscle", "common"}, {"joint", "hip+knee"}, {"value", v},
                 {"unit", "s"}, {"ci95", {v - 1.96 * se, v + 1.96 * se}}});
  }
  if (m.spec.twitch != 0) {
    const double v = m.spec.twitch, se = m.spec.twitch_se;
    a.push_back({{"name", "muscle_twitch"}, {"muscle", "common"}, {"joint", "hip+knee"}, {"value", v}, {"unit", "s"},
                 {"ci95", {v - 1.96 * se, v + 1.96 * se}}});
  }
  for (const auto& dl : m.spec.delay_s) {
    const double se = m.spec.delay_se.count(dl.first) ? m.spec.delay_se.at(dl.first) : 0.0;
    a.push_back({{"name", "electromechanical_delay"}, {"muscle", MuscleName(dl.first)}, {"joint", Joints(dl.first)},
                 {"value", dl.second}, {"unit", "s"}, {"ci95", {dl.second - 1.96 * se, dl.second + 1.96 * se}}});
  }
  if (m.spec.a_shape != 0)
    a.push_back({{"name", "activation_nonlinearity"}, {"joint", "hip+knee"}, {"value", m.spec.a_shape}, {"unit", "1"},
                 {"ci95", {m.spec.a_shape - 1.96 * m.spec.a_shape_se, m.spec.a_shape + 1.96 * m.spec.a_shape_se}}});
  for (const EmgTerm& t : m.terms) {
    std::string name;
    if (t.kind == TermKind::kPassive) name = kPassiveMoment;
    if (t.kind == TermKind::kAlphaQ) name = "moment_arm_angle";
    if (t.kind == TermKind::kAlpha && t.proxy) name = "missing_channel";
    if (name.empty()) continue;
    json e = {{"name", name}, {"joint", kJoint[t.joint]}, {"value", t.value}, {"unit", t.Unit()},
              {"ci95", {t.value - 1.96 * t.se, t.value + 1.96 * t.se}}, {"parameter", t.Name()}};
    if (!t.channel.empty()) e["channel"] = t.channel;
    a.push_back(e);
  }
  if (m.spec.robust) a.push_back({{"name", "robust_fit"}, {"joint", "hip+knee"}, {"value", kSpikeMads}, {"unit", "scaled MAD"}});
  return a;
}


std::string Validation(const EmgDiagnosis& d) {
  return std::string("causes chosen by cross-validation: ") +
         (d.folds_are_recordings ? "each of the " + std::to_string(d.folds) + " recordings left out in turn"
                                 : std::to_string(d.folds) + " contiguous blocks of the recording left out in turn") +
         "; also fit on the first " + NumberText(100 * (1 - d.holdout_fraction)) +
         " % of every recording and scored on the rest, for comparison; scores over samples within " +
         NumberText(kSpikeMads) + " scaled MADs of the median moment";
}

}  // namespace

std::string EmgDiagnosisJson(const EmgDiagnosis& d) {
  using nlohmann::json;
  json j;
  j["effects"] = Effects(d);
  // Every alpha of the calibration with its muscle's sign: held at zero by the signed fit, or not.
  j["alphas"] = json::array();
  for (const EmgTerm& t : d.calibration.terms)
    if (t.kind == TermKind::kAlpha)
      j["alphas"].push_back({{"parameter", t.Name()}, {"joint", kJoint[t.joint]}, {"value", t.value}, {"se", t.se},
                             {"unit", t.Unit()}, {"expected_sign", t.ExpectedSign()}, {"held_at_zero", t.held}});
  j["signed_alphas"] = d.calibration.spec.signed_alphas;
  const EmgTorqueModel& first = d.steps.front().model;
  const EmgTorqueModel& last = d.steps.back().model;
  for (int k = 0; k < 2; ++k) {
    const double b = first.figures[k].rms_heldout_trim, a = last.figures[k].rms_heldout_trim;
    const double cb = first.figures[k].rms_cv, ca = last.figures[k].rms_cv;
    j["joints"][kJoint[k]] = {{"rmse_before", b}, {"rmse_after", a}, {"gain_pct", b > 0 ? 100 * (1 - a / b) : 0.0},
                              {"cv_rmse_before", cb}, {"cv_rmse_after", ca},
                              {"cv_gain_pct", cb > 0 ? 100 * (1 - ca / cb) : 0.0},
                              {"cv_r2_before", first.figures[k].r2_cv}, {"cv_r2_after", last.figures[k].r2_cv},
                              {"r2_before", first.figures[k].r2_heldout_trim},
                              {"r2_after", last.figures[k].r2_heldout_trim},
                              {"r2_before_all_samples", first.figures[k].r2_heldout},
                              {"r2_after_all_samples", last.figures[k].r2_heldout},
                              {"band_hz", d.ceiling[k].band_hz},
                              {"moment_share_above_band", d.ceiling[k].share_above},
                              {"estimate_share_above_band", d.ceiling[k].estimate_share},
                              {"r2_ceiling_band", d.ceiling[k].r2}};
  }
  j["validation"] = {{"method", Validation(d)},
                     {"holdout_fraction", d.holdout_fraction},
                     {"folds", d.folds},
                     {"leave_one_record_out", d.folds_are_recordings}};
  j["selection"] = d.selection;
  j["steps"] = json::array();
  for (const EmgStep& s : d.steps) {
    json x = {{"added", s.added}, {"why", s.why}, {"bic", s.model.bic}};
    for (int k = 0; k < 2; ++k) {
      const EmgJointFigures& F = s.model.figures[k];
      x[kJoint[k]] = {{"r2_cv", F.r2_cv}, {"rms_cv", F.rms_cv},
                      {"r2_fit", F.r2_fit}, {"r2_heldout", F.r2_heldout_trim}, {"rms_heldout", F.rms_heldout_trim},
                      {"r2_heldout_all_samples", F.r2_heldout}, {"rms_heldout_all_samples", F.rms_heldout}};
    }
    j["steps"].push_back(x);
  }
  j["candidates"] = json::array();
  for (const EmgCandidateScore& c : d.scores) {
    json x = {{"round", c.round}, {"label", c.label}, {"delta_bic", c.delta_bic},
              {"heldout_gain_pct", {{"hip", c.gain_pct[0]}, {"knee", c.gain_pct[1]}}},
              {"cv_gain_pct", {{"hip", c.cv_gain_pct[0]}, {"knee", c.cv_gain_pct[1]}}}, {"selected", c.added},
              {"verdict", c.verdict}};
    j["candidates"].push_back(x);
  }
  j["missing_channels"] = d.missing;
  j["notes"] = d.notes;
  j["records"] = d.sources;
  return j.dump(2) + "\n";
}

std::string EmgDiagnosisHtml(const EmgDiagnosis& d) {
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>exotwin EMG model diagnosis</title>"
       "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}</style></head><body>\n"
       "<h1>exotwin EMG model diagnosis</h1><p>Recordings: ";
  for (size_t i = 0; i < d.sources.size(); ++i) o << (i ? ", " : "") << "<code>" << HtmlEscape(d.sources[i]) << "</code>";
  o << ". " << HtmlEscape(Validation(d)) << " (contact spikes of inverse dynamics left out for every model alike).</p>";
  if (!d.notes.empty()) {
    o << "<ul>";
    for (const auto& n : d.notes) o << "<li>" << HtmlEscape(n) << "</li>";
    o << "</ul>";
  }
  o << "<h2>Steps from the linear form to the final model</h2><table><tr><th>step</th><th>added</th><th>why</th>"
       "<th>hip R&sup2; cross-validated</th><th>knee R&sup2; cross-validated</th>"
       "<th>hip R&sup2; last 30 %</th><th>hip rms (N m)</th><th>knee R&sup2; last 30 %</th><th>knee rms (N m)</th>"
       "<th>hip / knee R&sup2; all last-30 % samples</th></tr>";
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const auto& F = d.steps[i].model.figures;
    o << "<tr><td>" << i << "</td><td>" << HtmlEscape(d.steps[i].added) << "</td><td>" << HtmlEscape(d.steps[i].why) << "</td><td>"
      << NumberText(F[0].r2_cv, 3) << "</td><td>" << NumberText(F[1].r2_cv, 3) << "</td><td>"
      << NumberText(F[0].r2_heldout_trim, 3) << "</td><td>" << NumberText(F[0].rms_heldout_trim, 3) << "</td><td>"
      << NumberText(F[1].r2_heldout_trim, 3) << "</td><td>" << NumberText(F[1].rms_heldout_trim, 3) << "</td><td>"
      << NumberText(F[0].r2_heldout, 3) << " / " << NumberText(F[1].r2_heldout, 3) << "</td></tr>";
  }
  o << "</table><p>Band ceiling (the final model on every sample): ";
  for (int k = 0; k < 2; ++k)
    o << (k ? "; " : "") << kJoint[k] << ": the estimate holds all but " << NumberText(100 * kBandResidue, 2)
      << " % of its variance below " << NumberText(d.ceiling[k].band_hz, 3) << " Hz, the measured moment has "
      << NumberText(100 * d.ceiling[k].share_above, 3) << " % of its variance above, so R&sup2; cannot pass "
      << NumberText(d.ceiling[k].r2, 3) << " in that band";
  o << ".</p><h2>Named causes (fitted on every sample)</h2><table><tr><th>cause</th><th>joint</th><th>value</th>"
       "<th>95 % interval</th></tr>";
  for (const auto& e : Effects(d)) {
    o << "<tr><td>" << HtmlEscape(e["name"].get<std::string>()) << (e.contains("muscle") ? " " + e["muscle"].get<std::string>() : "")
      << (e.contains("parameter") ? " " + HtmlEscape(e["parameter"].get<std::string>()) : "") << "</td><td>"
      << e["joint"].get<std::string>() << "</td><td>" << NumberText(e["value"].get<double>(), 4) << " "
      << HtmlEscape(e["unit"].get<std::string>()) << "</td><td>";
    if (e.contains("ci95")) o << NumberText(e["ci95"][0].get<double>(), 4) << " .. " << NumberText(e["ci95"][1].get<double>(), 4);
    o << "</td></tr>";
  }
  o << "</table>";
  if (!d.missing.empty()) {
    o << "<p>Muscles without a channel: ";
    for (const auto& m : d.missing) o << m << " ";
    o << "</p>";
  }
  o << "<h2>Selection</h2><ol>";
  for (const auto& s : d.selection) o << "<li>" << HtmlEscape(s) << "</li>";
  o << "</ol><h2>Candidates</h2><table><tr><th>round</th><th>candidate</th><th>&Delta;BIC</th><th>cross-validated gain hip</th>"
       "<th>knee</th><th>last-30 % gain hip</th><th>knee</th><th>verdict</th></tr>";
  for (const auto& c : d.scores) {
    o << "<tr><td>" << c.round << "</td><td>" << HtmlEscape(c.label) << "</td><td>" << NumberText(c.delta_bic, 4) << "</td><td>"
      << NumberText(c.cv_gain_pct[0], 3) << " %</td><td>" << NumberText(c.cv_gain_pct[1], 3) << " %</td><td>"
      << NumberText(c.gain_pct[0], 3) << " %</td><td>" << NumberText(c.gain_pct[1], 3) << " %</td>";
    o << "<td>" << (c.added ? "<b>" : "") << HtmlEscape(c.verdict) << (c.added ? "</b>" : "") << "</td></tr>";
  }
  o << "</table>";
  if (d.t.size() > d.split + 2) {
    const size_t a = d.split, b = std::min(d.t.size(), a + static_cast<size_t>(10.0 / std::max(1e-6, d.t[1] - d.t[0])));
    const std::vector<double> t(d.t.begin() + a, d.t.begin() + b);
    auto part = [&](const std::vector<double>& y) { return std::vector<double>(y.begin() + a, y.begin() + b); };
    for (int j = 0; j < 2; ++j)
      o << "<h2>" << kJoint[j] << " (held-out, first 10 s)</h2>"
        << SvgChart(std::string(kJoint[j]) + " moment", "t (s)", "N m",
                    {{t, part(d.measured[j]), "#000", "inverse dynamics"},
                     {t, part(d.linear[j]), "#d62728", "linear form"},
                     {t, part(d.final_[j]), "#1f77b4", "final model"}});
  }
  // The musculoskeletal form (issue 42): forms, reachable shares, every muscle's parameters and bounds,
  // and its force and fibre length over the first recording.
  const EmgMskModel& m = d.calibration.msk;
  if (m.present && !d.t.empty()) {
    o << "<h2>Musculoskeletal form</h2><p>Cross-validated R<sup>2</sup>: hip " << NumberText(m.r2_cv[0], 3) << " ("
      << (d.calibration.msk_form[0] ? "chosen" : "linear form chosen") << "), knee " << NumberText(m.r2_cv[1], 3) << " ("
      << (d.calibration.msk_form[1] ? "chosen" : "linear form chosen") << "). The recorded muscles can reach "
      << NumberText(100 * m.reachable_share[0], 3) << " % of the hip's and " << NumberText(100 * m.reachable_share[1], 3)
      << " % of the knee's calibration moment at full activation and 1.5 F_max, "
      << NumberText(100 * m.reachable_share_recorded[0], 3) << " % / " << NumberText(100 * m.reachable_share_recorded[1], 3)
      << " % at their recorded activation. Tendon " << (m.elastic_tendon ? "elastic" : "rigid") << ". Delay " << NumberText(1e3 * m.delay, 3)
      << " ms, twitch " << NumberText(1e3 * m.twitch, 3) << " ms, A " << NumberText(m.a_shape, 3) << ".</p>";
    o << "<table><tr><th>channel</th><th>path</th><th>F_max (N)</th><th>strength (x F_max; bounds 0.5-1.5, a synthesized term 0-1.5)</th><th>l_ts (m) [bounds]</th>"
         "<th>l_opt (m) [bounds]</th><th>force over the trial (N) min / mean / max</th><th>fibre length (l_opt) min / max</th></tr>";
    const EmgRecording& rec0 = d.first_recording;
    const EmgMskSeries ser = rec0.size() ? MskSeries(m, rec0) : EmgMskSeries{};
    for (size_t c = 0; c < m.muscles.size(); ++c) {
      const EmgMskMuscle& x = m.muscles[c];
      o << "<tr><td>" << HtmlEscape(x.Label()) << "</td><td>" << HtmlEscape(MusculotendonPathSource(x.muscle)) << "</td><td>"
        << NumberText(x.nominal.f_max, 4) << "</td><td>" << NumberText(x.strength, 3) << "</td><td>" << NumberText(x.l_ts, 4)
        << " [" << NumberText((1 - kTendonSlackChange) * x.nominal.l_ts, 4) << ", "
        << NumberText((1 + kTendonSlackChange) * x.nominal.l_ts, 4) << "]</td><td>" << NumberText(x.l_opt, 4) << " ["
        << NumberText((1 - kOptimalFibreChange) * x.nominal.l_opt, 4) << ", "
        << NumberText((1 + kOptimalFibreChange) * x.nominal.l_opt, 4) << "]</td>";
      if (c < ser.force.size() && !ser.force[c].empty()) {
        const auto f = std::minmax_element(ser.force[c].begin(), ser.force[c].end());
        double mean = 0;
        for (double v : ser.force[c]) mean += v / static_cast<double>(ser.force[c].size());
        o << "<td>" << NumberText(*f.first, 3) << " / " << NumberText(mean, 3) << " / " << NumberText(*f.second, 3)
          << "</td><td>" << NumberText(x.fibre_lo, 3) << " / " << NumberText(x.fibre_hi, 3) << "</td>";
      }
      o << "</tr>";
    }
    o << "</table>";
    if (!ser.force.empty()) {
      static const char* kColour[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                                      "#7f7f7f", "#bcbd22", "#17becf"};
      const size_t b = std::min(rec0.size(), static_cast<size_t>(10.0 / std::max(1e-6, rec0.t[1] - rec0.t[0])));
      const std::vector<double> t(rec0.t.begin(), rec0.t.begin() + static_cast<long>(b));
      std::vector<SvgSeries> fs, ls;
      std::map<Muscle, size_t> synthesized;  // a synthesized muscle: one series, its terms' forces summed
      for (size_t c = 0; c < ser.force.size(); ++c) {
        const EmgMskMuscle& x = m.muscles[c];
        const std::vector<double> f(ser.force[c].begin(), ser.force[c].begin() + static_cast<long>(b));
        if (x.synthesized) {
          const auto [it, first] = synthesized.emplace(x.muscle, fs.size());
          if (!first) {
            for (size_t i = 0; i < b; ++i) fs[it->second].y[i] += f[i];
            continue;
          }
        }
        const char* col = kColour[fs.size() % 10];
        const std::string name = x.MuscleLabel();
        fs.push_back({t, f, col, name});
        ls.push_back({t, std::vector<double>(ser.fibre[c].begin(), ser.fibre[c].begin() + static_cast<long>(b)), col, name});
      }
      o << "<h2>Muscle forces (first 10 s)</h2>" << SvgChart("muscle force", "t (s)", "N", fs)
        << "<h2>Fibre lengths (first 10 s)</h2>" << SvgChart("fibre length", "t (s)", "l / l_opt", ls);
    }
  }
  o << "</body></html>\n";
  return o.str();
}

void WriteEmgDiagnosis(const EmgDiagnosis& d, const std::string& dir) {
  CreateOutputFolder(dir);
  WriteFileAtomic(dir + "/diagnosis.json", EmgDiagnosisJson(d));
  WriteFileAtomic(dir + "/report.html", EmgDiagnosisHtml(d));
}

}  // namespace exotwin
