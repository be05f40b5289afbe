#include "runner/sweep_plots.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdio>

#include "dsp/statistics.h"
#include "core/error.h"
#include "runner/sweep_table.h"

namespace exotwin {
namespace {

constexpr double kPanelW = 420, kPanelH = 260, kTop = 50;
constexpr double kMarginL = 50, kMarginR = 15, kMarginT = 30, kMarginB = 40;

std::string Fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

std::string Escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '"') o += "&quot;";
    else o += c;
  }
  return o;
}

// Short label of a value for an axis tick.
std::string Tick(double v) { return Fmt("%.4g", v); }

std::string Panel(const Histogram& h, double x0, double y0) {
  std::string s = "<g transform=\"translate(" + Fmt("%.0f", x0) + "," + Fmt("%.0f", y0) + ")\">\n";
  const double pw = kPanelW - kMarginL - kMarginR, ph = kPanelH - kMarginT - kMarginB;
  s += "<text x=\"" + Fmt("%.0f", kPanelW / 2) + "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">" +
       Escape(h.title) + " (n=" + std::to_string(h.n) + ")</text>\n";
  s += "<rect x=\"" + Fmt("%.0f", kMarginL) + "\" y=\"" + Fmt("%.0f", kMarginT) + "\" width=\"" + Fmt("%.0f", pw) +
       "\" height=\"" + Fmt("%.0f", ph) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  const int cmax = h.counts.empty() ? 0 : *std::max_element(h.counts.begin(), h.counts.end());
  if (h.n == 0 || cmax == 0) {
    s += "<text x=\"" + Fmt("%.0f", kMarginL + pw / 2) + "\" y=\"" + Fmt("%.0f", kMarginT + ph / 2) +
         "\" text-anchor=\"middle\" font-size=\"12\">no data</text>\n</g>\n";
    return s;
  }
  const double span = h.hi > h.lo ? h.hi - h.lo : 1.0;
  auto X = [&](double v) { return kMarginL + (h.hi > h.lo ? (v - h.lo) / span : 0.5) * pw; };
  const double bw = pw / h.counts.size();
  for (size_t b = 0; b < h.counts.size(); ++b) {
    const double bh = ph * h.counts[b] / cmax;
    s += "<rect x=\"" + Fmt("%.2f", kMarginL + b * bw) + "\" y=\"" + Fmt("%.2f", kMarginT + ph - bh) +
         "\" width=\"" + Fmt("%.2f", std::max(0.0, bw - 1)) + "\" height=\"" + Fmt("%.2f", bh) +
         "\" fill=\"#4a7ab5\"/>\n";
  }
  auto vline = [&](double v, const char* colour, const char* dash) {
    s += "<line x1=\"" + Fmt("%.2f", X(v)) + "\" x2=\"" + Fmt("%.2f", X(v)) + "\" y1=\"" + Fmt("%.0f", kMarginT) +
         "\" y2=\"" + Fmt("%.0f", kMarginT + ph) + "\" stroke=\"" + colour + "\" stroke-dasharray=\"" + dash +
         "\" stroke-width=\"1.5\"/>\n";
  };
  vline(h.mean, "#c0392b", "6,3");
  vline(h.p5, "#555", "2,3");
  vline(h.p95, "#555", "2,3");
  const double yb = kMarginT + ph + 15;
  s += "<text x=\"" + Fmt("%.0f", kMarginL) + "\" y=\"" + Fmt("%.0f", yb) + "\" font-size=\"11\">" + Tick(h.lo) + "</text>\n";
  s += "<text x=\"" + Fmt("%.0f", kMarginL + pw) + "\" y=\"" + Fmt("%.0f", yb) +
       "\" font-size=\"11\" text-anchor=\"end\">" + Tick(h.hi) + "</text>\n";
  s += "<text x=\"" + Fmt("%.0f", kMarginL + pw / 2) + "\" y=\"" + Fmt("%.0f", yb + 16) +
       "\" font-size=\"11\" text-anchor=\"middle\">mean " + Tick(h.mean) + " (red), p5 " + Tick(h.p5) + ", p95 " +
       Tick(h.p95) + " (dotted)</text>\n";
  s += "<text x=\"" + Fmt("%.0f", kMarginL - 6) + "\" y=\"" + Fmt("%.0f", kMarginT + 10) +
       "\" font-size=\"11\" text-anchor=\"end\">" + std::to_string(cmax) + "</text>\n";
  s += "<text x=\"" + Fmt("%.0f", kMarginL - 6) + "\" y=\"" + Fmt("%.0f", kMarginT + ph) +
       "\" font-size=\"11\" text-anchor=\"end\">0</text>\n</g>\n";
  return s;
}

}  // namespace

Histogram MakeHistogram(const std::string& title, std::vector<double> values, int bins) {
  Histogram h;
  h.title = title;
  h.counts.assign(std::max(1, bins), 0);
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  h.n = values.size();
  if (values.empty()) return h;
  std::sort(values.begin(), values.end());
  h.lo = values.front();
  h.hi = values.back();
  double sum = 0;
  for (double v : values) sum += v;
  h.mean = sum / values.size();
  h.p5 = Percentile(values, 0.05);
  h.p95 = Percentile(values, 0.95);
  const int nb = static_cast<int>(h.counts.size());
  for (double v : values) {
    int b = h.hi > h.lo ? static_cast<int>((v - h.lo) / (h.hi - h.lo) * nb) : nb / 2;
    h.counts[std::clamp(b, 0, nb - 1)]++;
  }
  return h;
}

std::string HistogramGridSvg(const std::string& title, const std::vector<Histogram>& panels) {
  const int cols = 2, rows = std::max<int>(1, (panels.size() + 1) / 2);
  const double w = cols * kPanelW, h = kTop + rows * kPanelH;
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                  Fmt("%.0f", w) + "\" height=\"" + Fmt("%.0f", h) + "\" viewBox=\"0 0 " + Fmt("%.0f", w) + " " +
                  Fmt("%.0f", h) + "\" font-family=\"sans-serif\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + Fmt("%.0f", w / 2) + "\" y=\"30\" text-anchor=\"middle\" font-size=\"17\">" + Escape(title) +
       "</text>\n";
  for (size_t i = 0; i < panels.size(); ++i)
    s += Panel(panels[i], (i % cols) * kPanelW, kTop + (i / cols) * kPanelH);
  return s + "</svg>\n";
}

ChartFrame LayoutLineChart(const LineChart& c) {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const LineSeries& s : c.series) {
    if (s.x.size() != s.y.size())
      throw InputError("line chart '" + c.title + "': series '" + s.label + "' has " + std::to_string(s.x.size()) +
                       " x and " + std::to_string(s.y.size()) + " y values (expected the same number)");
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]), ymax = std::max(ymax, s.y[i]);
    }
  }
  if (!std::isfinite(xmin)) throw InputError("line chart '" + c.title + "': no finite point to draw");
  for (const LineMarker& m : c.markers)
    if (std::isfinite(m.x)) xmin = std::min(xmin, m.x), xmax = std::max(xmax, m.x);
  auto pad = [](double lo, double hi, double* a, double* b) {
    const double d = hi > lo ? 0.05 * (hi - lo) : std::max(1.0, 0.1 * std::abs(lo));
    *a = lo - d, *b = hi + d;
  };
  ChartFrame f;
  pad(xmin, xmax, &f.x0, &f.x1);
  pad(ymin, ymax, &f.y0, &f.y1);
  f.left = 80, f.right = c.width - 25, f.top = 50, f.bottom = c.height - 60;
  return f;
}

std::string LineChartSvg(const LineChart& c) {
  const ChartFrame f = LayoutLineChart(c);
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                  Fmt("%.0f", c.width) + "\" height=\"" + Fmt("%.0f", c.height) + "\" viewBox=\"0 0 " +
                  Fmt("%.0f", c.width) + " " + Fmt("%.0f", c.height) + "\" font-family=\"sans-serif\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + Fmt("%.0f", c.width / 2) + "\" y=\"28\" text-anchor=\"middle\" font-size=\"16\">" +
       Escape(c.title) + "</text>\n";
  // Grid and ticks: about 8 (x) and 6 (y) steps of 1, 2 or 5 x 10^k.
  auto step_of = [](double span, int n) {
    const double raw = span / n, p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0})
      if (m * p >= raw) return m * p;
    return 10 * p;
  };
  const double xs = step_of(f.x1 - f.x0, 8), ys = step_of(f.y1 - f.y0, 6);
  for (double v = std::ceil(f.x0 / xs) * xs; v <= f.x1; v += xs) {
    const double x = f.X(v);
    s += "<line x1=\"" + Fmt("%.2f", x) + "\" x2=\"" + Fmt("%.2f", x) + "\" y1=\"" + Fmt("%.0f", f.top) + "\" y2=\"" +
         Fmt("%.0f", f.bottom) + "\" stroke=\"#e3e3e3\"/>\n";
    s += "<text x=\"" + Fmt("%.2f", x) + "\" y=\"" + Fmt("%.0f", f.bottom + 18) +
         "\" text-anchor=\"middle\" font-size=\"12\">" + Tick(std::abs(v) < 1e-9 * xs ? 0.0 : v) + "</text>\n";
  }
  for (double v = std::ceil(f.y0 / ys) * ys; v <= f.y1; v += ys) {
    const double y = f.Y(v);
    s += "<line x1=\"" + Fmt("%.0f", f.left) + "\" x2=\"" + Fmt("%.0f", f.right) + "\" y1=\"" + Fmt("%.2f", y) +
         "\" y2=\"" + Fmt("%.2f", y) + "\" stroke=\"#e3e3e3\"/>\n";
    s += "<text x=\"" + Fmt("%.0f", f.left - 8) + "\" y=\"" + Fmt("%.2f", y + 4) +
         "\" text-anchor=\"end\" font-size=\"12\">" + Tick(std::abs(v) < 1e-9 * ys ? 0.0 : v) + "</text>\n";
  }
  s += "<rect x=\"" + Fmt("%.0f", f.left) + "\" y=\"" + Fmt("%.0f", f.top) + "\" width=\"" + Fmt("%.0f", f.right - f.left) +
       "\" height=\"" + Fmt("%.0f", f.bottom - f.top) + "\" fill=\"none\" stroke=\"#444\"/>\n";
  s += "<text x=\"" + Fmt("%.0f", (f.left + f.right) / 2) + "\" y=\"" + Fmt("%.0f", c.height - 18) +
       "\" text-anchor=\"middle\" font-size=\"13\">" + Escape(c.x_label) + "</text>\n";
  s += "<text transform=\"translate(20," + Fmt("%.0f", (f.top + f.bottom) / 2) +
       ") rotate(-90)\" text-anchor=\"middle\" font-size=\"13\">" + Escape(c.y_label) + "</text>\n";
  int row = 0;
  for (const LineMarker& m : c.markers) {
    if (!std::isfinite(m.x)) continue;
    const double x = f.X(m.x);
    s += "<line class=\"marker\" x1=\"" + Fmt("%.2f", x) + "\" x2=\"" + Fmt("%.2f", x) + "\" y1=\"" + Fmt("%.0f", f.top) +
         "\" y2=\"" + Fmt("%.0f", f.bottom) + "\" stroke=\"" + m.colour + "\" stroke-dasharray=\"6,4\"/>\n";
    s += "<text x=\"" + Fmt("%.2f", x + 4) + "\" y=\"" + Fmt("%.0f", f.top + 16 + 16 * row++) + "\" font-size=\"12\" fill=\"" +
         m.colour + "\">" + Escape(m.label) + "</text>\n";
  }
  for (const LineSeries& ser : c.series) {
    std::string pts;
    auto flush = [&] {
      if (!pts.empty())
        s += "<polyline class=\"series\" data-label=\"" + Escape(ser.label) + "\" fill=\"none\" stroke=\"" + ser.colour +
             "\" stroke-width=\"2\" points=\"" + pts + "\"/>\n";
      pts.clear();
    };
    for (size_t i = 0; i < ser.x.size(); ++i) {
      if (!std::isfinite(ser.x[i]) || !std::isfinite(ser.y[i])) {
        flush();
        continue;
      }
      const std::string px = Fmt("%.2f", f.X(ser.x[i])), py = Fmt("%.2f", f.Y(ser.y[i]));
      pts += (pts.empty() ? "" : " ") + px + "," + py;
      if (ser.x.size() <= 60)  // dots on the samples of short series
        s += "<circle cx=\"" + px + "\" cy=\"" + py + "\" r=\"3\" fill=\"" + ser.colour + "\"/>\n";
    }
    flush();
  }
  row = 0;
  for (const LineSeries& ser : c.series) {
    const double y = f.top + 18 + 18 * row++;
    s += "<line x1=\"" + Fmt("%.0f", f.right - 230) + "\" x2=\"" + Fmt("%.0f", f.right - 205) + "\" y1=\"" +
         Fmt("%.0f", y - 4) + "\" y2=\"" + Fmt("%.0f", y - 4) + "\" stroke=\"" + ser.colour + "\" stroke-width=\"2\"/>\n";
    s += "<text x=\"" + Fmt("%.0f", f.right - 198) + "\" y=\"" + Fmt("%.0f", y) + "\" font-size=\"12\">" +
         Escape(ser.label) + "</text>\n";
  }
  return s + "</svg>\n";
}

std::string SweepHistogramsSvg(const std::string& scenario, const std::vector<SweepRow>& rows) {
  static const char* const kKeys[] = {
      "tracking_rms_hip_deg", "tracking_rms_knee_deg", "tracking_max_hip_deg", "tracking_max_knee_deg",
      "torque_rms_hip",       "torque_rms_knee",       "torque_max_hip",       "torque_max_knee",
      "safe_reaction_s",      "torque_max_after_safe", "subject_weight_kg"};
  std::vector<Histogram> panels;
  size_t runs = 0;
  for (const char* key : kKeys) {
    std::vector<double> v;
    bool any = false;
    for (const SweepRow& r : rows) {
      if (r.scenario != scenario || (r.status != "ok" && r.status != "check_failed")) continue;
      auto it = r.values.find(key);
      if (it == r.values.end()) continue;
      any = true;
      v.push_back(it->second);
    }
    if (std::string(key) == "safe_reaction_s")  // -1 = no fault or no reaction: not a time
      v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return x < 0; }), v.end());
    if (any && !(std::string(key) == "safe_reaction_s" && v.empty())) {
      runs = std::max(runs, v.size());
      // Rice rule: 2 n^(1/3) bins, 5 to 30.
      const int bins = std::clamp(static_cast<int>(std::ceil(2 * std::cbrt(double(v.size())))), 5, 30);
      panels.push_back(MakeHistogram(key, v, bins));
    }
  }
  return HistogramGridSvg("sweep " + scenario + ": " + std::to_string(runs) + " subjects", panels);
}

std::string PlotFileName(const std::string& scenario) {
  std::string f;
  for (char c : scenario) f += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  return f + ".svg";
}

}  // namespace exotwin
