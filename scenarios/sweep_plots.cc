#include "scenarios/sweep_plots.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdio>

#include "scenarios/sweep_table.h"

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
