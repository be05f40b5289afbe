// Sweep plots (scenarios/sweep_plots.h): the line chart's polylines, read back from the SVG text and
// mapped through the chart's axes, give the data again; non-finite points split a line; markers sit
// at their x; bad input is an InputError. Histograms count every finite value once.
#include "runner/sweep_plots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"

namespace exotwin {
namespace {

// The "x,y x,y ..." point lists of the polylines labelled `label`, in document order.
std::vector<std::vector<std::pair<double, double>>> Polylines(const std::string& svg, const std::string& label) {
  std::vector<std::vector<std::pair<double, double>>> out;
  const std::string head = "<polyline class=\"series\" data-label=\"" + label + "\"";
  for (size_t at = svg.find(head); at != std::string::npos; at = svg.find(head, at + 1)) {
    const size_t p = svg.find("points=\"", at) + 8;
    std::istringstream in(svg.substr(p, svg.find('"', p) - p));
    std::vector<std::pair<double, double>> pts;
    std::string xy;
    while (in >> xy) {
      const size_t comma = xy.find(',');
      pts.push_back({std::atof(xy.substr(0, comma).c_str()), std::atof(xy.substr(comma + 1).c_str())});
    }
    out.push_back(pts);
  }
  return out;
}

LineChart TwoCurves() {
  LineChart c;
  c.title = "criteria <over> B_v";
  LineSeries line{"2x + 1", {}, {}, "#c0392b"}, parabola{"x^2 / 4", {}, {}, "#2c6fbb"};
  for (int i = 0; i <= 18; ++i) {
    const double x = -0.5 + 0.25 * i;
    line.x.push_back(x), line.y.push_back(2 * x + 1);
    parabola.x.push_back(x), parabola.y.push_back(x * x / 4);
  }
  c.series = {line, parabola};
  c.markers = {{1.56, "paper 1.56"}, {5.0, "beyond the data"}};
  return c;
}

TEST(LineChart, PolylinesMapBackToTheData) {
  const LineChart c = TwoCurves();
  const ChartFrame f = LayoutLineChart(c);
  // x spans the data and the markers (-0.5 .. 5), y the data (0 .. 9), each padded by 5 %.
  EXPECT_NEAR(f.x0, -0.5 - 0.275, 1e-12);
  EXPECT_NEAR(f.x1, 5.0 + 0.275, 1e-12);
  EXPECT_NEAR(f.y0, 0.0 - 0.45, 1e-12);
  EXPECT_NEAR(f.y1, 9.0 + 0.45, 1e-12);
  const std::string svg = LineChartSvg(c);
  for (const LineSeries& s : c.series) {
    const auto lines = Polylines(svg, s.label);
    ASSERT_EQ(lines.size(), 1u) << s.label;
    ASSERT_EQ(lines[0].size(), s.x.size()) << s.label;
    for (size_t i = 0; i < s.x.size(); ++i) {
      // Inverse of ChartFrame::X / Y; coordinates are printed with 2 decimals (0.005 units).
      const double x = f.x0 + (lines[0][i].first - f.left) / (f.right - f.left) * (f.x1 - f.x0);
      const double y = f.y0 + (f.bottom - lines[0][i].second) / (f.bottom - f.top) * (f.y1 - f.y0);
      EXPECT_NEAR(x, s.x[i], 0.006 * (f.x1 - f.x0) / (f.right - f.left)) << s.label << " point " << i;
      EXPECT_NEAR(y, s.y[i], 0.006 * (f.y1 - f.y0) / (f.bottom - f.top)) << s.label << " point " << i;
    }
  }
  // Markers: a dashed line at their x; the title is escaped.
  char marker[64];
  std::snprintf(marker, sizeof(marker), "<line class=\"marker\" x1=\"%.2f\"", f.X(1.56));
  EXPECT_NE(svg.find(marker), std::string::npos) << marker;
  EXPECT_NE(svg.find("criteria &lt;over&gt; B_v"), std::string::npos);
  EXPECT_EQ(svg.find("<over>"), std::string::npos);
}

TEST(LineChart, NonFinitePointsSplitTheLine) {
  LineChart c;
  c.series = {{"gap", {0, 1, 2, 3, 4}, {0, 1, std::numeric_limits<double>::quiet_NaN(), 3, 4}, "#000"}};
  const auto lines = Polylines(LineChartSvg(c), "gap");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].size(), 2u);
  EXPECT_EQ(lines[1].size(), 2u);
}

TEST(LineChart, BadInputIsAnInputError) {
  LineChart c;
  c.series = {{"mismatch", {0, 1}, {0}, "#000"}};
  EXPECT_THROW(LayoutLineChart(c), InputError);
  c.series = {{"nothing finite", {std::nan("")}, {1}, "#000"}};
  EXPECT_THROW(LineChartSvg(c), InputError);
}

TEST(Histogram, CountsEveryFiniteValueOnce) {
  const Histogram h = MakeHistogram("t", {1, 2, 2, 3, std::nan(""), 10}, 3);
  EXPECT_EQ(h.n, 5u);
  int total = 0;
  for (int k : h.counts) total += k;
  EXPECT_EQ(total, 5);
  EXPECT_DOUBLE_EQ(h.mean, 18.0 / 5);
  EXPECT_EQ(h.counts.back(), 1);  // 10 alone in the top bin [7, 10]
}

}  // namespace
}  // namespace exotwin
