// Self-contained SVG charts for the HTML reports (diagnose, emg-fit): line or scatter series with
// axes, end ticks, a title and a legend; no script, no external file.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// One series: x, y of equal length (non-finite points skipped), colour, legend label, dots or line.
struct SvgSeries {
  std::vector<double> x, y;
  std::string color, label;
  bool dots = false;
};

// s with <, > and & escaped for HTML text.
std::string HtmlEscape(const std::string& s);

// One chart of `series` (logy: log10 axis, values clamped at 1e-12). Returns the <svg> element.
std::string SvgChart(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                     const std::vector<SvgSeries>& series, bool logy = false);

}  // namespace exotwin
