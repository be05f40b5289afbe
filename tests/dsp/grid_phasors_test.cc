// GridPhasors against the closed form exp(i 2 pi f x): at every grid frequency within a few ulps of
// cos/sin taken directly (the steps' rounding grows with the distance from the last anchor, bounded
// by it), the anchors and At the same bits as cos/sin, and an anchor of 1 never steps.
#include "dsp/grid_phasors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"

namespace exotwin::dsp {
namespace {

TEST(GridPhasors, StepsStayOnTheClosedFormAndAnchorsAreIt) {
  Rng rng(5);
  std::vector<double> x(500);
  for (double& v : x) v = rng.Uniform(-3, 3);  // angles (rad) or times (s)
  const double f0 = 1.0, df = 0.1;
  for (int anchor : {1, 16, 32}) {
    GridPhasors ph(x, df, anchor);
    double worst = 0;
    for (int g = 0; g <= 90; ++g) {
      const double f = f0 + g * df;
      ph.AtGrid(g, f);
      for (size_t i = 0; i < x.size(); ++i) {
        const double a = 2 * M_PI * f * x[i];
        if (g % anchor == 0) {
          ASSERT_EQ(ph.re()[i], std::cos(a));
          ASSERT_EQ(ph.im()[i], std::sin(a));
        }
        worst = std::max({worst, std::abs(ph.re()[i] - std::cos(a)), std::abs(ph.im()[i] - std::sin(a))});
      }
    }
    // 32 steps of a unit complex product: each about 2 ulps; the angles' own rounding (|a| < 200 rad,
    // 3e-14 rad) besides.
    EXPECT_LT(worst, 1e-12) << "anchor " << anchor;
    ph.At(2.345);
    EXPECT_EQ(ph.re()[7], std::cos(2 * M_PI * 2.345 * x[7]));
    EXPECT_EQ(ph.im()[7], std::sin(2 * M_PI * 2.345 * x[7]));
  }
  EXPECT_THROW(GridPhasors(x, df, 0), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin::dsp
