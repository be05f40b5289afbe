// Summary plots of a sweep, as SVG written by hand (no plotting library): per scenario, a grid of
// histograms of its key metrics over the subjects, with mean and p5/p95 marks.
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

// A file name for a scenario's plot: the name with characters outside [A-Za-z0-9._-] as '_', ".svg".
std::string PlotFileName(const std::string& scenario);

}  // namespace exotwin
