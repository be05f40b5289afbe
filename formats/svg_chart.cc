#include "formats/svg_chart.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "formats/number_text.h"

namespace exotwin {

std::string HtmlEscape(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}

// One SVG chart (line or scatter series) with axes, ticks at the ends, a title and a legend.
std::string SvgChart(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                     const std::vector<SvgSeries>& series, bool logy) {
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
  o << "<text x='" << W / 2 << "' y='16' text-anchor='middle' font-size='13'>" << HtmlEscape(title) << "</text>";
  o << "<rect x='" << L << "' y='" << T << "' width='" << W - L - R << "' height='" << H - T - B
    << "' fill='none' stroke='#888'/>";
  o << "<text x='" << L << "' y='" << H - 20 << "' font-size='10'>" << NumberText(x0, 3) << "</text>";
  o << "<text x='" << W - R << "' y='" << H - 20 << "' font-size='10' text-anchor='end'>" << NumberText(x1, 3) << "</text>";
  o << "<text x='" << (L + W) / 2 << "' y='" << H - 6 << "' font-size='11' text-anchor='middle'>"
    << HtmlEscape(xlabel) << "</text>";
  const double yl0 = logy ? std::pow(10, y0) : y0, yl1 = logy ? std::pow(10, y1) : y1;
  o << "<text x='" << L - 4 << "' y='" << H - B << "' font-size='10' text-anchor='end'>" << NumberText(yl0, 3) << "</text>";
  o << "<text x='" << L - 4 << "' y='" << T + 10 << "' font-size='10' text-anchor='end'>" << NumberText(yl1, 3) << "</text>";
  o << "<text x='12' y='" << (T + H - B) / 2 << "' font-size='11' text-anchor='middle' transform='rotate(-90 12 "
    << (T + H - B) / 2 << ")'>" << HtmlEscape(ylabel) << "</text>";
  if (!logy && y0 < 0 && y1 > 0)
    o << "<line x1='" << L << "' x2='" << W - R << "' y1='" << Y(0) << "' y2='" << Y(0) << "' stroke='#ddd'/>";
  int li = 0;
  for (const auto& s : series) {
    if (s.dots) {
      o << "<g fill='" << s.color << "' fill-opacity='0.35'>";
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i])) o << "<circle cx='" << NumberText(X(s.x[i]), 5) << "' cy='" << NumberText(Y(s.y[i]), 5) << "' r='1.2'/>";
      o << "</g>";
    } else {
      o << "<polyline fill='none' stroke-width='1' stroke='" << s.color << "' points='";
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i])) o << NumberText(X(s.x[i]), 5) << "," << NumberText(Y(s.y[i]), 5) << " ";
      o << "'/>";
    }
    o << "<text x='" << L + 8 << "' y='" << T + 14 + 13 * li << "' font-size='11' fill='" << s.color << "'>"
      << HtmlEscape(s.label) << "</text>";
    ++li;
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace exotwin
