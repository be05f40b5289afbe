#include "analysis/diagnose_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/units.h"

namespace exotwin {
namespace {

struct Series {
  std::vector<double> x, y;
  std::string color, label;
  bool dots = false;
};

std::string Esc(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}

std::string Fmt(double v, int prec = 3) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.*g", prec, v);
  return b;
}

// One SVG chart (line or scatter series) with axes, ticks at the ends, a title and a legend.
std::string Chart(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                  const std::vector<Series>& series, bool logy = false) {
  const double W = 560, H = 260, L = 60, R = 10, T = 24, B = 36;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  auto ty = [&](double y) { return logy ? std::log10(std::max(y, 1e-12)) : y; };
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, ty(s.y[i])), y1 = std::max(y1, ty(s.y[i]));
    }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  auto X = [&](double x) { return L + (x - x0) / (x1 - x0) * (W - L - R); };
  auto Y = [&](double y) { return T + (1 - (ty(y) - y0) / (y1 - y0)) * (H - T - B); };
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
    << "' style='background:#fff;border:1px solid #ccc;margin:4px'>";
  o << "<text x='" << W / 2 << "' y='16' text-anchor='middle' font-size='13'>" << Esc(title) << "</text>";
  o << "<rect x='" << L << "' y='" << T << "' width='" << W - L - R << "' height='" << H - T - B
    << "' fill='none' stroke='#888'/>";
  o << "<text x='" << L << "' y='" << H - 20 << "' font-size='10'>" << Fmt(x0) << "</text>";
  o << "<text x='" << W - R << "' y='" << H - 20 << "' font-size='10' text-anchor='end'>" << Fmt(x1) << "</text>";
  o << "<text x='" << (L + W) / 2 << "' y='" << H - 6 << "' font-size='11' text-anchor='middle'>"
    << Esc(xlabel) << "</text>";
  const double yl0 = logy ? std::pow(10, y0) : y0, yl1 = logy ? std::pow(10, y1) : y1;
  o << "<text x='" << L - 4 << "' y='" << H - B << "' font-size='10' text-anchor='end'>" << Fmt(yl0) << "</text>";
  o << "<text x='" << L - 4 << "' y='" << T + 10 << "' font-size='10' text-anchor='end'>" << Fmt(yl1) << "</text>";
  o << "<text x='12' y='" << (T + H - B) / 2 << "' font-size='11' text-anchor='middle' transform='rotate(-90 12 "
    << (T + H - B) / 2 << ")'>" << Esc(ylabel) << "</text>";
  if (!logy && y0 < 0 && y1 > 0)
    o << "<line x1='" << L << "' x2='" << W - R << "' y1='" << Y(0) << "' y2='" << Y(0) << "' stroke='#ddd'/>";
  int li = 0;
  for (const auto& s : series) {
    if (s.dots) {
      o << "<g fill='" << s.color << "' fill-opacity='0.35'>";
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i])) o << "<circle cx='" << Fmt(X(s.x[i]), 5) << "' cy='" << Fmt(Y(s.y[i]), 5) << "' r='1.2'/>";
      o << "</g>";
    } else {
      o << "<polyline fill='none' stroke-width='1' stroke='" << s.color << "' points='";
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i])) o << Fmt(X(s.x[i]), 5) << "," << Fmt(Y(s.y[i]), 5) << " ";
      o << "'/>";
    }
    o << "<text x='" << L + 8 << "' y='" << T + 14 + 13 * li << "' font-size='11' fill='" << s.color << "'>"
      << Esc(s.label) << "</text>";
    ++li;
  }
  o << "</svg>\n";
  return o.str();
}

// Amplitude spectrum (N m) of x[a, b) by a direct DFT of a strided copy, f in (0, fmax].
Series Spectrum(const std::vector<double>& t, const std::vector<double>& x, size_t a, size_t b,
                const std::string& color, const std::string& label) {
  Series s;
  s.color = color, s.label = label;
  const size_t stride = std::max<size_t>(1, (b - a) / 4000);
  std::vector<double> tt, xx;
  double mean = 0;
  for (size_t i = a; i < b; i += stride) tt.push_back(t[i]), xx.push_back(x[i]), mean += x[i];
  mean /= static_cast<double>(xx.size());
  const double T = std::max(tt.back() - tt.front(), 1e-6);
  const double fmax = std::min(20.0, 0.5 * static_cast<double>(xx.size()) / T);
  for (double f = 1.0 / T; f <= fmax; f += std::max(1.0 / T, fmax / 400)) {
    double re = 0, im = 0;
    for (size_t i = 0; i < xx.size(); ++i) {
      const double ph = 2 * M_PI * f * tt[i];
      re += (xx[i] - mean) * std::cos(ph), im += (xx[i] - mean) * std::sin(ph);
    }
    s.x.push_back(f);
    s.y.push_back(2 * std::hypot(re, im) / static_cast<double>(xx.size()));
  }
  return s;
}

}  // namespace

std::string DiagnosisReportHtml(const Diagnosis& d, const std::string& params_path,
                                const std::string& measured_path) {
  const auto& k = d.kin;
  const size_t n = k.t.size();
  const char* jn[2] = {"hip", "knee"};
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>exotwin diagnosis</title>"
       "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}</style></head><body>\n";
  o << "<h1>exotwin diagnosis</h1><p>Twin: <code>" << Esc(params_path) << "</code>, measured: <code>"
    << Esc(measured_path) << "</code>, " << n << " samples, " << Fmt(k.t.back() - k.t.front(), 4)
    << " s; derivatives: " << Esc(k.derivative_source) << ".</p>\n";
  o << "<h2>Filtering</h2><p>Measured and predicted torque are low-passed alike before residuals are "
       "formed (parallel filtering), the angles differentiated below that filter's cutoff: "
    << Esc(d.cutoff.why) << ".</p>";
  if (!d.cutoff.candidates_hz.empty()) {
    o << "<table><tr><th>cutoff (Hz)</th><th>generic fit, held-out rmse hip (N m)</th>"
         "<th>generic fit, held-out rmse knee (N m)</th></tr>";
    for (size_t i = 0; i < d.cutoff.candidates_hz.size(); ++i)
      o << "<tr><td>" << (d.cutoff.candidates_hz[i] == d.cutoff.hz ? "<b>" : "") << Fmt(d.cutoff.candidates_hz[i])
        << (d.cutoff.candidates_hz[i] == d.cutoff.hz ? "</b>" : "") << "</td><td>" << Fmt(d.cutoff.heldout_rmse[0][i], 4)
        << "</td><td>" << Fmt(d.cutoff.heldout_rmse[1][i], 4) << "</td></tr>";
    o << "</table>";
  }
  o << "<h2>What the twin gets wrong, and why</h2>";
  if (d.effects.empty()) {
    o << "<p><b>No effect named</b>: no candidate explanation is supported by the data (information "
         "criterion and held-out error).</p>";
  } else {
    o << "<table><tr><th>effect</th><th>joint</th><th>value</th><th>95 % interval</th><th>extra</th>"
         "<th>explains (held-out residual)</th></tr>";
    for (const auto& e : d.effects) {
      std::string extra = e.effect.axis.empty() ? "" : "axis " + e.effect.axis + " ";
      for (const auto& f : e.effect.fields) extra += f.first + " = " + Fmt(f.second, 4) + " ";
      o << "<tr><td>" << e.effect.name << "</td><td>" << e.effect.joint << "</td><td>"
        << Fmt(e.effect.value, 4) << " " << Esc(e.effect.unit) << "</td><td>" << Fmt(e.ci_lo, 4) << " .. "
        << Fmt(e.ci_hi, 4) << "</td><td>" << Esc(extra) << "</td><td>" << Fmt(e.explained_pct, 3)
        << " %</td></tr>";
    }
    o << "</table>";
  }
  o << "<h2>Gain of the extended twin (held-out " << Fmt(100 * d.holdout_fraction) << " %)</h2>"
    << "<table><tr><th>joint</th><th>rmse before (N m)</th><th>rmse after (N m)</th><th>gain</th>"
       "<th>noise (N m)</th></tr>";
  for (int j = 0; j < 2; ++j)
    o << "<tr><td>" << jn[j] << "</td><td>" << Fmt(d.joints[j].rmse_before, 4) << "</td><td>"
      << Fmt(d.joints[j].rmse_after, 4) << "</td><td>" << Fmt(d.joints[j].gain_pct, 3) << " %</td><td>"
      << Fmt(d.noise[j], 3) << "</td></tr>";
  o << "</table>";
  if (d.records.size() > 1) {
    o << "<h2>Records</h2><table><tr><th>record</th><th>samples</th><th>hip: held-out 30 % before / after (N m)</th>"
         "<th>knee: held-out 30 %</th><th>hip: whole record left out</th><th>knee: whole record left out</th></tr>";
    auto cell = [&](const JointScore& s) {
      return Fmt(s.rmse_before, 4) + " / " + Fmt(s.rmse_after, 4) + " (" + Fmt(s.gain_pct, 3) + " %)";
    };
    for (const auto& r : d.records)
      o << "<tr><td>" << Esc(r.source) << "</td><td>" << r.samples << "</td><td>" << cell(r.split[0]) << "</td><td>"
        << cell(r.split[1]) << "</td><td>" << cell(r.left_out[0]) << "</td><td>" << cell(r.left_out[1]) << "</td></tr>";
    o << "<tr><th>all</th><td></td><td>" << cell(d.joints[0]) << "</td><td>" << cell(d.joints[1]) << "</td><td>"
      << cell(d.left_out[0]) << "</td><td>" << cell(d.left_out[1]) << "</td></tr></table>"
      << "<p>Plots below: the first record.</p>";
  }
  o << "<p><small>" << Esc(d.method) << "</small></p>";
  o << "<h2>Selection</h2><ol>";
  for (const auto& s : d.selection) o << "<li>" << Esc(s) << "</li>";
  o << "</ol>";
  if (!d.implausible.empty()) {
    o << "<p>Fitted alone but outside their physical range, so not named:</p><ul>";
    for (const auto& s : d.implausible) o << "<li>" << Esc(s) << "</li>";
    o << "</ul>";
  }
  o << "<h2>Unexplained structure</h2>";
  if (d.unexplained.empty()) o << "<p>None above the noise.</p>";
  for (const auto& u : d.unexplained)
    o << "<p><b>" << u.joint << "</b>: rms " << Fmt(u.rms) << " N m (below 5 Hz), dominant "
      << Fmt(u.dominant_hz) << " Hz; correlation with angle " << Fmt(u.corr_q, 2) << ", velocity "
      << Fmt(u.corr_qd, 2) << ", acceleration " << Fmt(u.corr_qdd, 2) << ", time " << Fmt(u.corr_t, 2)
      << " &mdash; " << Esc(u.hint) << ".</p>";
  o << "<h2>Candidates</h2><table><tr><th>candidate</th><th>&Delta;BIC</th><th>held-out gain</th>"
       "<th>chosen</th></tr>";
  for (const auto& s : d.scores)
    o << "<tr><td>" << Esc(s.label) << "</td><td>" << Fmt(s.delta_bic, 4) << "</td><td>"
      << Fmt(s.heldout_gain_pct, 3) << " %</td><td>" << (s.selected ? "yes" : "") << "</td></tr>";
  o << "</table>";
  if (!d.collinear.empty()) {
    o << "<p>Nearly collinear on this record (told apart only by the small differences in shape, "
         "the coupling between joints and the held-out data; their intervals are wide when both are "
         "plausible):</p><ul>";
    for (const auto& c : d.collinear) o << "<li>" << Esc(c) << "</li>";
    o << "</ul>";
  }
  // Plots per joint.
  const size_t a0 = d.split, win = std::min(n - d.split, static_cast<size_t>(std::max<size_t>(
                                                     1, static_cast<size_t>(10.0 * n / std::max(k.t.back() - k.t.front(), 1e-9)))));
  const size_t st_line = std::max<size_t>(1, win / 1500), st_dot = std::max<size_t>(1, n / 1500);
  for (int j = 0; j < 2; ++j) {
    o << "<h2>" << jn[j] << "</h2>\n";
    Series m{{}, {}, "#000", "measured (filtered alike)"}, b{{}, {}, "#d62728", "twin before"}, a{{}, {}, "#1f77b4", "extended twin"};
    for (size_t i = a0; i < a0 + win; i += st_line) {
      m.x.push_back(k.t[i]), m.y.push_back(d.measured[j][i]);
      b.x.push_back(k.t[i]), b.y.push_back(d.before[j][i]);
      a.x.push_back(k.t[i]), a.y.push_back(d.after[j][i]);
    }
    o << Chart("measured vs predicted torque (held-out)", "t (s)", "tau_S (N m)", {m, b, a});
    std::vector<double> rb(n), ra(n);
    for (size_t i = 0; i < n; ++i) rb[i] = d.measured[j][i] - d.before[j][i], ra[i] = d.measured[j][i] - d.after[j][i];
    const std::vector<double> qdeg = [&] { std::vector<double> v(n); for (size_t i = 0; i < n; ++i) v[i] = k.q[j][i] * kDegPerRad; return v; }();
    struct Axis { const std::vector<double>* x; const char* label; } axes[4] = {
        {&qdeg, "angle (deg)"}, {&k.qd[j], "velocity (rad/s)"}, {&k.qdd[j], "acceleration (rad/s^2)"}, {&k.t, "t (s)"}};
    for (const auto& ax : axes) {
      Series sb{{}, {}, "#d62728", "residual before", true}, sa{{}, {}, "#1f77b4", "residual after (held-out)", true};
      for (size_t i = 0; i < n; i += st_dot) {
        sb.x.push_back((*ax.x)[i]), sb.y.push_back(rb[i]);
        sa.x.push_back((*ax.x)[i]), sa.y.push_back(ra[i]);
      }
      o << Chart(std::string("residual vs ") + ax.label, ax.label, "N m", {sb, sa});
    }
    o << Chart("residual amplitude spectrum", "f (Hz)", "N m",
               {Spectrum(k.t, rb, 0, n, "#d62728", "before"), Spectrum(k.t, ra, d.split, n, "#1f77b4", "after (held-out)")}, true);
  }
  o << "</body></html>\n";
  return o.str();
}

}  // namespace exotwin
