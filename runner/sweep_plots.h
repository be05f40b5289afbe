// Summary plots of a sweep, as SVG written by hand (no plotting library): per scenario, a grid of
// histograms of its key metrics over the subjects, with mean and p5/p95 marks; and line charts of
// criteria over a swept parameter (the HAL viscous sweep, Lee & Sankai Fig. 9).
#pragma once
#include <string>
#include <vector>

namespace exotwin {

struct SweepRow;

// One histogram panel: `bins` equal bins over [min, max] of the finite values.
struct Histogram {
  std::string title;
  double lo = 0, hi = 0, mean = 0, p5 = 0, p95 = 0;
  std::vector<int> counts;
  size_t n = 0;
};
// Builds a histogram (bins >= 1); with no finite value n = 0 and the counts are zero.
Histogram MakeHistogram(const std::string& title, std::vector<double> values, int bins);

// SVG document: a grid of histogram panels (2 columns) under a title.
std::string HistogramGridSvg(const std::string& title, const std::vector<Histogram>& panels);

// The plot of one scenario of a sweep: histograms of the key metrics (tracking, torque, safety
// reaction) present in its completed rows, plus the subjects' weight.
std::string SweepHistogramsSvg(const std::string& scenario, const std::vector<SweepRow>& rows);

// A line chart: series of (x, y) on shared linear axes, a legend, dashed vertical markers.
struct LineSeries {
  std::string label;
  std::vector<double> x, y;  // same length; non-finite points break the line
  std::string colour = "#000000";
};
struct LineMarker {
  double x = 0;
  std::string label, colour = "#555555";
};
struct LineChart {
  std::string title, x_label, y_label;
  std::vector<LineSeries> series;
  std::vector<LineMarker> markers;
  double width = 900, height = 560;  // SVG user units (pixels)
};
// Data -> SVG coordinates of the plot area: the axes span [x0, x1] x [y0, y1] (the data and
// markers, padded by 5 %) over [left, right] x [top, bottom].
struct ChartFrame {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  double left = 0, right = 1, top = 0, bottom = 1;
  double X(double x) const { return left + (x - x0) / (x1 - x0) * (right - left); }
  double Y(double y) const { return bottom - (y - y0) / (y1 - y0) * (bottom - top); }
};
// Axes of a chart. Throws InputError if a series' x and y differ in length or no point is finite.
ChartFrame LayoutLineChart(const LineChart& c);
// SVG document of the chart: each series a <polyline class="series" data-label="..."> (one per run
// of finite points, coordinates with 2 decimals), markers as dashed <line class="marker">.
std::string LineChartSvg(const LineChart& c);

// A file name for a scenario's plot: the name with characters outside [A-Za-z0-9._-] as '_', ".svg".
std::string PlotFileName(const std::string& scenario);

}  // namespace exotwin
