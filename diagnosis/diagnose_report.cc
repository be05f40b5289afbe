#include "diagnosis/diagnose_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "dsp/grid_phasors.h"
#include "formats/number_text.h"
#include "formats/svg_chart.h"
#include "core/parallel_for.h"
#include "core/units.h"

namespace exotwin {
namespace {

// Amplitude spectrum (N m) of x(i), i in [a, b), by a direct DFT of a strided copy (at most ~4000
// samples), f on a uniform grid in (0, fmax], the phasors stepped along the grid (dsp::GridPhasors).
template <class X>
SvgSeries Spectrum(const std::vector<double>& t, X x, size_t a, size_t b, const std::string& color,
                   const std::string& label) {
  constexpr int kAnchor = 32;
  SvgSeries s;
  s.color = color, s.label = label;
  const size_t stride = std::max<size_t>(1, (b - a) / 4000);
  std::vector<double> tt, xx;
  double mean = 0;
  for (size_t i = a; i < b; i += stride) tt.push_back(t[i]), xx.push_back(x(i)), mean += xx.back();
  mean /= static_cast<double>(xx.size());
  for (double& v : xx) v -= mean;
  const double T = std::max(tt.back() - tt.front(), 1e-6);
  const double fmax = std::min(20.0, 0.5 * static_cast<double>(xx.size()) / T);
  const double f0 = 1.0 / T, df = std::max(1.0 / T, fmax / 400);
  const size_t N = xx.size();
  dsp::GridPhasors phasors(std::move(tt), df, kAnchor);
  const std::vector<double>& re = phasors.re();
  const std::vector<double>& im = phasors.im();
  for (int k = 0;; ++k) {
    const double f = f0 + k * df;
    if (f > fmax) break;
    phasors.AtGrid(k, f);
    double sum_re = 0, sum_im = 0;
    for (size_t i = 0; i < N; ++i) sum_re += xx[i] * re[i], sum_im += xx[i] * im[i];
    s.x.push_back(f);
    s.y.push_back(2 * std::hypot(sum_re, sum_im) / static_cast<double>(N));
  }
  return s;
}

// The named effects' table; `explains`: of what explained_pct is the share.
std::string EffectsTable(const Diagnosis& d, const std::string& explains) {
  std::ostringstream o;
  o << "<table><tr><th>effect</th><th>joint</th><th>value</th><th>95 % interval</th><th>extra</th>"
       "<th>explains (" << explains << ")</th></tr>";
  for (const auto& e : d.effects) {
    std::string extra = e.effect.axis.empty() ? "" : "axis " + e.effect.axis + " ";
    for (const auto& f : e.effect.fields) extra += f.first + " = " + NumberText(f.second, 4) + " ";
    o << "<tr><td>" << e.effect.name << "</td><td>" << e.effect.joint << "</td><td>" << NumberText(e.effect.value, 4)
      << " " << HtmlEscape(e.effect.unit) << "</td><td>" << NumberText(e.ci_lo, 4) << " .. " << NumberText(e.ci_hi, 4)
      << "</td><td>" << HtmlEscape(extra) << "</td><td>" << NumberText(e.explained_pct, 3) << " %</td></tr>";
  }
  o << "</table>";
  return o.str();
}

// The forward simulation's table: per record (and pooled) the RMS simulated-angle error of the twin
// given vs the extended twin, held-out and whole records left out.
std::string SimulationTable(const Diagnosis& d) {
  const SimulationScores& S = d.simulation;
  std::ostringstream o;
  auto deg = [&](const JointScore& s) {
    return NumberText(s.rmse_before * kDegPerRad, 3) + " / " + NumberText(s.rmse_after * kDegPerRad, 3) + " deg (" +
           NumberText(s.gain_pct, 3) + " %)";
  };
  o << "<table><tr><th>record</th><th>hip: held-out, rigid / extended</th><th>knee: held-out</th>"
    << (d.leave_one_out ? "<th>hip: whole record left out</th><th>knee: whole record left out</th>" : "") << "</tr>";
  for (const auto& r : d.records) {
    o << "<tr><td>" << HtmlEscape(r.source) << "</td><td>" << deg(r.sim_split[0]) << "</td><td>" << deg(r.sim_split[1]) << "</td>";
    if (d.leave_one_out) o << "<td>" << deg(r.sim_left_out[0]) << "</td><td>" << deg(r.sim_left_out[1]) << "</td>";
    o << "</tr>";
  }
  o << "<tr><th>all</th><td>" << deg(S.split[0]) << "</td><td>" << deg(S.split[1]) << "</td>";
  if (d.leave_one_out) o << "<td>" << deg(S.left_out[0]) << "</td><td>" << deg(S.left_out[1]) << "</td>";
  o << "</tr>";
  if (S.torque_fit_done) {  // a motion fit: the torque fit's twin on the same rows
    o << "<tr><th>all, the torque fit's twin</th><td>" << deg(S.torque_fit_split[0]) << "</td><td>"
      << deg(S.torque_fit_split[1]) << "</td>";
    if (d.leave_one_out)
      o << "<td>" << deg(S.torque_fit_left_out[0]) << "</td><td>" << deg(S.torque_fit_left_out[1]) << "</td>";
    o << "</tr>";
  }
  o << "</table><p>RMS error of the simulated angle against the measured one"
    << (S.torque_fit_done ? "; the last row: the torque fit's extended twin on the same rows (each record left out with the "
                            "torque fit's values without it" +
                                (S.torque_fit_not_carried.empty()
                                     ? std::string(")")
                                     : "; not carried by the plant, left out: " + HtmlEscape([&] {
                                         std::string t;
                                         for (const auto& x : S.torque_fit_not_carried) t += (t.empty() ? "" : ", ") + x;
                                         return t;
                                       }()) + ")")
                          : std::string())
    << ".</p>";
  if (!S.torque_fit_why.empty()) o << "<p>" << HtmlEscape(S.torque_fit_why) << ".</p>";
  return o.str();
}

// "named X % of what is explainable": the named model's held-out share of the model given's residual
// sum of squares against the larger of it and the black box's (named + black box); words where
// neither removes anything; the RMS of what the black box adds, against the material floor.
std::string CeilingText(const JointCeiling& c, double floor) {
  if (!c.done) return "not assessed";
  std::string s = "the named model removes " + NumberText(c.named_pct, 3) + " % of the model given's held-out residual "
                  "sum of squares, with a black box beside it " + NumberText(c.black_box_pct, 3) + " %";
  const double explainable = std::max(c.named_pct, c.black_box_pct);
  if (!(explainable > 0)) return s + ": nothing explainable beyond the noise";
  const double added = c.given_rms * std::sqrt(std::max(0.0, c.black_box_pct - c.named_pct) / 100);
  return s + ": named " + NumberText(100 * std::max(0.0, c.named_pct) / explainable, 3) +
         " % of what is explainable (the black box adds " + NumberText(added, 2) + " N m RMS, " +
         (added < floor ? "below" : "above") + " the material floor)";
}

// The completeness verdicts (table's and final model) and the final model's residual tests and ceiling.
std::string CompletenessSection(const Diagnosis& d) {
  const char* jn[2] = {"hip", "knee"};
  const int j0 = d.extended.one_joint ? 1 : 0;
  auto verdict = [](const JointCompleteness& c) {
    return std::string(!c.assessed ? "not assessed (held-out part too short)" : c.complete ? "complete" : "<b>incomplete</b>");
  };
  std::ostringstream o;
  o << "<h2>Completeness and ceiling</h2><p>Residual tests of the held-out torque residual (whiteness: Ljung-Box; "
       "cross-correlation with the states; the nonlinear correlation tests of Billings &amp; Voon 1986), on rows "
       "decimated where the filtered noise is near-independent, each test Bonferroni over its lags and the tests "
       "(family-wise " << NumberText(100 * kCompletenessAlpha) << " %); structure below the material floor passes.</p><ul>";
  for (int j = j0; j < 2; ++j) {
    const JointCompleteness &t = d.table_model.completeness[j], &f = d.final_model.completeness[j];
    o << "<li><b>" << jn[j] << "</b>: the table's model " << verdict(t) << ", the final model " << verdict(f) << " ("
      << f.rows << " rows, every " << f.step << " samples; floor " << NumberText(f.floor, 3) << " N m, residual RMS "
      << NumberText(f.rms, 3) << " N m); " << HtmlEscape(CeilingText(d.final_model.ceiling[j], f.floor)) << ".</li>";
  }
  o << "</ul><table><tr><th>test (final model)</th>";
  for (int j = j0; j < 2; ++j) o << "<th>" << jn[j] << ": statistic / threshold (p, size N m)</th>";
  o << "</tr>";
  const std::vector<CompletenessTest>& names = d.final_model.completeness[1].tests;
  for (size_t k = 0; k < names.size(); ++k) {
    o << "<tr><td>" << names[k].name << "</td>";
    for (int j = j0; j < 2; ++j) {
      o << "<td>";
      for (const CompletenessTest& t : d.final_model.completeness[j].tests)
        if (t.name == names[k].name)
          o << (t.pass ? "" : "<b>") << NumberText(t.statistic, 3) << " / " << NumberText(t.threshold, 3) << " (p "
            << NumberText(t.p_value, 2) << ", " << NumberText(t.size, 2) << ")" << (t.pass ? "" : " fails</b>");
      o << "</td>";
    }
    o << "</tr>";
  }
  o << "</table>";
  return o.str();
}

// The motion fit's report (diagnosis/motion_fit.h).
// Each named term's component-plus-residual plots (diagnose.h TermPlot): the residual plus the term's
// own torque against its shape, with the line value * shape, and against each signal it reads.
std::string TermPlotsHtml(const Diagnosis& d) {
  std::ostringstream o;
  for (const TermPlot& p : d.term_plots) {
    o << "<p>" << HtmlEscape(p.joint) << ": the residual plus the term's own torque (points) lies on the "
      << "term's line where its form is right; spread about the line is what the final model leaves.</p>";
    SvgSeries pts{p.shape, p.partial, "#d62728", "residual + term (fit rows)", true}, line{{}, {}, "#1f77b4", "term"};
    double lo = 0, hi = 0;
    for (double x : p.shape) lo = std::min(lo, x), hi = std::max(hi, x);
    line.x = {lo, hi}, line.y = {p.value * lo, p.value * hi};
    o << SvgChart(p.joint + ": residual + " + NumberText(p.value) + " * " + p.expr, "term shape (" + p.expr + ", filtered)",
                  "tau_S residual + term (N m)", {pts, line});
    for (const auto& sig : p.signals) {
      SvgSeries r{sig.second, p.partial, "#d62728", "residual + term", true},
          t{sig.second, {}, "#1f77b4", "term", true};
      for (double x : p.shape) t.y.push_back(p.value * x);
      o << SvgChart(p.joint + ": residual + term against " + sig.first, sig.first, "tau_S residual + term (N m)", {r, t});
    }
  }
  return o.str();
}

std::string MotionReportHtml(const Diagnosis& d, const std::string& params_path, const std::string& measured_path) {
  const char* jn[2] = {"hip", "knee"};
  const int j0 = d.extended.one_joint ? 1 : 0;
  const SimulationScores& S = d.simulation;
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>exotwin diagnosis (motion fit)</title>"
       "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}</style></head><body>\n";
  o << "<h1>exotwin diagnosis: motion fit</h1><p>Twin: <code>" << HtmlEscape(params_path) << "</code>, measured: <code>"
    << HtmlEscape(measured_path) << "</code>.</p><p><small>" << HtmlEscape(d.method) << "</small></p>";
  o << "<h2>What the twin's motion gets wrong, and why</h2>";
  if (d.effects.empty()) {
    o << "<p><b>No effect named</b>: no candidate lowers the simulated-motion error enough (information criterion, "
         "held-out time" << (d.leave_one_out ? ", records left out" : "") << ", significance).</p>";
  } else {
    o << EffectsTable(d, "held-out simulated error");
  }
  o << "<h2>What the torque fit would have named</h2>";
  if (d.torque_named.empty()) o << "<p>Nothing.</p>";
  else {
    o << "<table><tr><th>effect</th><th>joint</th><th>torque fit's value</th><th>motion fit</th></tr>";
    for (const auto& e : d.torque_named) {
      std::string verdict = "named too";
      for (const TorqueOnlyEffect& t : d.torque_only)
        if (t.effect.name == e.effect.name && t.effect.joint == e.effect.joint && t.effect.axis == e.effect.axis)
          verdict = t.simulated ? "torque only: added at this value, the held-out simulated error changes by " +
                                      NumberText(t.heldout_change_pct[0], 3) + " % (hip), " +
                                      NumberText(t.heldout_change_pct[1], 3) + " % (knee)" +
                                      (std::isfinite(t.in_torque_twin_pct[0] + t.in_torque_twin_pct[1])
                                           ? "; in the torque fit's twin it changes it by " +
                                                 NumberText(t.in_torque_twin_pct[0], 3) + " % (hip), " +
                                                 NumberText(t.in_torque_twin_pct[1], 3) + " % (knee)"
                                           : std::string())
                                : "torque only: " + t.why;
      o << "<tr><td>" << e.effect.name << (e.effect.axis.empty() ? "" : "." + e.effect.axis) << "</td><td>"
        << e.effect.joint << "</td><td>" << NumberText(e.effect.value, 4) << " " << HtmlEscape(e.effect.unit)
        << "</td><td>" << HtmlEscape(verdict) << "</td></tr>";
    }
    o << "</table>";
  }
  o << "<h2>Forward simulation</h2><p>" << HtmlEscape(S.note) << "</p>" << SimulationTable(d);
  o << "<p>The torque reading drives the simulation (the twin's sensor reads the motor torque, HJ15 eq. 8), so it is "
       "no output of the fit: the plots show the angles.</p>";
  for (int j = j0; j < 2; ++j) {  // the first four windows of the first record's held-out part
    SvgSeries sm{{}, {}, "#000", "measured"}, sr{{}, {}, "#d62728", "twin given, simulated"},
        se{{}, {}, "#1f77b4", "motion fit, simulated"};
    for (size_t i = 0; i < S.t.size() && S.t[i] <= S.t.front() + 4 * S.horizon_s; ++i) {
      if (std::isnan(S.rigid[j][i])) continue;
      sm.x.push_back(S.t[i]), sm.y.push_back(S.measured[j][i] * kDegPerRad);
      sr.x.push_back(S.t[i]), sr.y.push_back(S.rigid[j][i] * kDegPerRad);
      se.x.push_back(S.t[i]), se.y.push_back(S.extended[j][i] * kDegPerRad);
    }
    o << "<h2>" << jn[j] << "</h2>"
      << SvgChart("measured vs fitted simulated angle (held-out, four windows of " + NumberText(S.horizon_s) + " s)",
                  "t (s)", "angle (deg)", {sm, sr, se});
  }
  o << CompletenessSection(d);
  o << "<h2>Selection</h2><ol>";
  for (const auto& s : d.selection) o << "<li>" << HtmlEscape(s) << "</li>";
  o << "</ol></body></html>\n";
  return o.str();
}


}  // namespace

std::string DiagnosisReportHtml(const Diagnosis& d, const std::string& params_path,
                                const std::string& measured_path) {
  if (d.fit == DiagnoseFit::kMotion) return MotionReportHtml(d, params_path, measured_path);
  const auto& k = d.kin;
  const size_t n = k.t.size();
  const char* jn[2] = {"hip", "knee"};
  const int j0 = d.extended.one_joint ? 1 : 0;  // a one-joint device: its joint (the knee) alone
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>exotwin diagnosis</title>"
       "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}</style></head><body>\n";
  o << "<h1>exotwin diagnosis</h1><p>Twin: <code>" << HtmlEscape(params_path) << "</code>, measured: <code>"
    << HtmlEscape(measured_path) << "</code>, " << n << " samples, " << NumberText(k.t.back() - k.t.front(), 4)
    << " s; derivatives: " << HtmlEscape(k.derivative_source) << ".</p>\n";
  o << "<h2>Filtering</h2><p>Measured and predicted torque are low-passed alike before residuals are "
       "formed (parallel filtering), the angles differentiated below that filter's cutoff: "
    << HtmlEscape(d.cutoff.why) << ".</p>";
  if (!d.cutoff.candidates_hz.empty()) {
    o << "<table><tr><th>cutoff (Hz)</th><th>generic fit, held-out rmse hip (N m)</th>"
         "<th>generic fit, held-out rmse knee (N m)</th></tr>";
    for (size_t i = 0; i < d.cutoff.candidates_hz.size(); ++i)
      o << "<tr><td>" << (d.cutoff.candidates_hz[i] == d.cutoff.hz ? "<b>" : "") << NumberText(d.cutoff.candidates_hz[i], 3)
        << (d.cutoff.candidates_hz[i] == d.cutoff.hz ? "</b>" : "") << "</td><td>" << NumberText(d.cutoff.heldout_rmse[0][i], 4)
        << "</td><td>" << NumberText(d.cutoff.heldout_rmse[1][i], 4) << "</td></tr>";
    o << "</table>";
  }
  o << "<h2>What the twin gets wrong, and why</h2>";
  if (d.effects.empty()) {
    o << "<p><b>No effect named</b>: no candidate explanation is supported by the data (information "
         "criterion and held-out error).</p>";
  } else {
    o << EffectsTable(d, "held-out residual");
    for (const auto& e : d.effects) {
      if (e.aliases.empty()) continue;
      o << "<p>The data cannot tell <b>" << e.effect.name << " (" << e.effect.joint
        << ")</b> from these, fitted in its place with the other named effects:</p><ul>";
      for (const EffectAlias& a : e.aliases) o << "<li>" << HtmlEscape(AliasText(a)) << "</li>";
      o << "</ul>";
    }
  }
  o << "<h2>Gain of the extended twin (held-out " << NumberText(100 * d.holdout_fraction, 3) << " %)</h2>"
    << "<table><tr><th>joint</th><th>rmse before (N m)</th><th>rmse after (N m)</th><th>gain</th>"
       "<th>noise (N m)</th></tr>";
  for (int j = j0; j < 2; ++j)
    o << "<tr><td>" << jn[j] << "</td><td>" << NumberText(d.joints[j].rmse_before, 4) << "</td><td>"
      << NumberText(d.joints[j].rmse_after, 4) << "</td><td>" << NumberText(d.joints[j].gain_pct, 3) << " %</td><td>"
      << NumberText(d.noise[j], 3) << "</td></tr>";
  o << "</table>";
  if (d.records.size() > 1) {
    o << "<h2>Records</h2><table><tr><th>record</th><th>samples</th><th>hip: held-out 30 % before / after (N m)</th>"
         "<th>knee: held-out 30 %</th><th>hip: whole record left out</th><th>knee: whole record left out</th></tr>";
    auto cell = [&](const JointScore& s) {
      return NumberText(s.rmse_before, 4) + " / " + NumberText(s.rmse_after, 4) + " (" + NumberText(s.gain_pct, 3) + " %)";
    };
    // A one-joint device has no hip: its cells stay empty.
    auto hip = [&](const JointScore& s) { return j0 == 0 ? cell(s) : std::string("&mdash;"); };
    for (const auto& r : d.records)
      o << "<tr><td>" << HtmlEscape(r.source) << "</td><td>" << r.samples << "</td><td>" << hip(r.split[0]) << "</td><td>"
        << cell(r.split[1]) << "</td><td>" << hip(r.left_out[0]) << "</td><td>" << cell(r.left_out[1]) << "</td></tr>";
    o << "<tr><th>all</th><td></td><td>" << hip(d.joints[0]) << "</td><td>" << cell(d.joints[1]) << "</td><td>"
      << hip(d.left_out[0]) << "</td><td>" << cell(d.left_out[1]) << "</td></tr></table>"
      << "<p>Plots below: the first record.</p>";
  }
  o << "<p><small>" << HtmlEscape(d.method) << "</small></p>";
  const SimulationScores& S = d.simulation;
  o << "<h2>Forward simulation</h2><p>" << HtmlEscape(S.note) << "</p>";
  if (S.done) o << SimulationTable(d);
  o << "<h2>Selection</h2><ol>";
  for (const auto& s : d.selection) o << "<li>" << HtmlEscape(s) << "</li>";
  o << "</ol>";
  if (!d.term_search.empty()) {
    o << "<h2>Terms beyond the table</h2><ul>";
    for (const auto& e : d.effects)
      if (!e.effect.expr.empty())
        o << "<li><b>" << HtmlEscape((e.effect.stage == "sensor" ? "tau_S(" : "tau_R(") + e.effect.joint + ") += " +
                                     NumberText(e.effect.value) + " * " + e.effect.expr)
          << "</b> (" << NumberText(e.explained_pct) << " % of the held-out residual)</li>";
    o << "</ul>";
    o << TermPlotsHtml(d);
    o << "<p>The search's steps:</p><ol>";
    for (const auto& s : d.term_search) o << "<li>" << HtmlEscape(s) << "</li>";
    o << "</ol>";
  }
  if (!d.implausible.empty()) {
    o << "<p>Fitted alone but outside their physical range, so not named:</p><ul>";
    for (const auto& s : d.implausible) o << "<li>" << HtmlEscape(s) << "</li>";
    o << "</ul>";
  }
  if (!d.not_identifiable.empty()) {
    o << "<p>Not identifiable from these records (even the edge of the physical range would not be significant):</p><ul>";
    for (const auto& s : d.not_identifiable) o << "<li>" << HtmlEscape(s) << "</li>";
    o << "</ul>";
  }
  o << "<h2>Unexplained structure</h2>";
  if (d.unexplained.empty()) o << "<p>None above the noise.</p>";
  for (const auto& u : d.unexplained)
    o << "<p><b>" << u.joint << "</b>: rms " << NumberText(u.rms, 3)
      << (d.fit == DiagnoseFit::kMotion ? " rad" : " N m") << " (below 5 Hz), dominant "
      << NumberText(u.dominant_hz, 3) << " Hz; correlation with angle " << NumberText(u.corr_q, 2) << ", velocity "
      << NumberText(u.corr_qd, 2) << ", acceleration " << NumberText(u.corr_qdd, 2) << ", time " << NumberText(u.corr_t, 2)
      << " &mdash; " << HtmlEscape(u.hint) << ".</p>";
  o << CompletenessSection(d);
  o << "<h2>Candidates</h2><table><tr><th>candidate</th><th>&Delta;BIC</th><th>held-out gain</th>"
       "<th>chosen</th></tr>";
  for (const auto& s : d.scores)
    o << "<tr><td>" << HtmlEscape(s.label) << "</td><td>" << NumberText(s.delta_bic, 4) << "</td><td>"
      << NumberText(s.heldout_gain_pct, 3) << " %</td><td>" << (s.selected ? "yes" : "") << "</td></tr>";
  o << "</table>";
  if (!d.collinear.empty()) {
    o << "<p>Nearly collinear on this record (told apart only by the small differences in shape, "
         "the coupling between joints and the held-out data; their intervals are wide when both are "
         "plausible):</p><ul>";
    for (const auto& c : d.collinear) o << "<li>" << HtmlEscape(c) << "</li>";
    o << "</ul>";
  }
  // Plots per joint.
  const size_t a0 = d.split, win = std::min(n - d.split, static_cast<size_t>(std::max<size_t>(
                                                     1, static_cast<size_t>(10.0 * n / std::max(k.t.back() - k.t.front(), 1e-9)))));
  const size_t st_line = std::max<size_t>(1, win / 1500), st_dot = std::max<size_t>(1, n / 1500);
  // Each joint's section into its own text, the two side by side (the same bytes on any thread count).
  std::string joint_html[2];
  ParallelFor(static_cast<size_t>(2 - j0), std::min(2, MachineCores()), [&](size_t jj) {
    const int j = j0 + static_cast<int>(jj);
    std::ostringstream o;
    o << "<h2>" << jn[j] << "</h2>\n";
    SvgSeries m{{}, {}, "#000", "measured (filtered alike)"}, b{{}, {}, "#d62728", "twin before"}, a{{}, {}, "#1f77b4", "extended twin"};
    for (size_t i = a0; i < a0 + win; i += st_line) {
      m.x.push_back(k.t[i]), m.y.push_back(d.measured[j][i]);
      b.x.push_back(k.t[i]), b.y.push_back(d.before[j][i]);
      a.x.push_back(k.t[i]), a.y.push_back(d.after[j][i]);
    }
    o << SvgChart("measured vs predicted torque (held-out)", "t (s)", "tau_S (N m)", {m, b, a});
    if (S.done && !S.t.empty()) {  // the first 10 s of the first record's held-out part
      SvgSeries sm{{}, {}, "#000", "measured"}, sr{{}, {}, "#d62728", "rigid twin, simulated"},
          se{{}, {}, "#1f77b4", "extended twin, simulated"};
      for (size_t i = 0; i < S.t.size() && S.t[i] <= S.t.front() + 10.0; ++i) {
        if (std::isnan(S.rigid[j][i])) continue;  // a window's restart
        sm.x.push_back(S.t[i]), sm.y.push_back(S.measured[j][i] * kDegPerRad);
        sr.x.push_back(S.t[i]), sr.y.push_back(S.rigid[j][i] * kDegPerRad);
        se.x.push_back(S.t[i]), se.y.push_back(S.extended[j][i] * kDegPerRad);
      }
      o << SvgChart("simulated vs measured angle (held-out, restarted every " + NumberText(S.horizon_s) + " s)", "t (s)",
                    "angle (deg)", {sm, sr, se});
    }
    // The residuals at the samples the plots take (a long record's memory: no record-long copies).
    auto rb = [&](size_t i) { return d.measured[j][i] - d.before[j][i]; };
    auto ra = [&](size_t i) { return d.measured[j][i] - d.after[j][i]; };
    struct Axis { const std::vector<double>* x; double scale; const char* label; } axes[4] = {
        {&k.q[j], kDegPerRad, "angle (deg)"}, {&k.qd[j], 1, "velocity (rad/s)"}, {&k.qdd[j], 1, "acceleration (rad/s^2)"},
        {&k.t, 1, "t (s)"}};
    for (const auto& ax : axes) {
      SvgSeries sb{{}, {}, "#d62728", "residual before", true}, sa{{}, {}, "#1f77b4", "residual after (held-out)", true};
      for (size_t i = 0; i < n; i += st_dot) {
        const double x = (*ax.x)[i] * ax.scale;  // exact where scale is 1
        sb.x.push_back(x), sb.y.push_back(rb(i));
        sa.x.push_back(x), sa.y.push_back(ra(i));
      }
      o << SvgChart(std::string("residual vs ") + ax.label, ax.label, "N m", {sb, sa});
    }
    o << SvgChart("residual amplitude spectrum", "f (Hz)", "N m",
               {Spectrum(k.t, rb, 0, n, "#d62728", "before"), Spectrum(k.t, ra, d.split, n, "#1f77b4", "after (held-out)")}, true);
    joint_html[j] = o.str();
  });
  o << joint_html[0] << joint_html[1] << "</body></html>\n";
  return o.str();
}

}  // namespace exotwin
