// Tests of runner/stress_metrics.h (LS05 eq. 12-18) on signals with closed-form integrals.
#include "runner/stress_metrics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace exotwin {
namespace {

TEST(StressMetrics, Eq12To18) {
  std::vector<double> tau, m;
  const double dt = 1e-3;
  for (int k = 0; k < 2000; ++k) {  // two periods of 1 Hz
    tau.push_back(3.0 * std::sin(2 * M_PI * (k + 0.5) * dt));
    m.push_back(-0.2);
  }
  EXPECT_NEAR(MeanAbsMoment(tau, dt), 3.0 * 2 / M_PI, 1e-4);  // mean |sin| = 2/pi
  EXPECT_NEAR(IntegratedMyoelectricity(m, dt), 0.4, 1e-12);   // 0.2 V x 2 s
  const std::vector<double> n = NormalizeByMax({1.0, 4.0, 2.0});
  EXPECT_DOUBLE_EQ(n[1], 1.0);
  EXPECT_DOUBLE_EQ(n[0], 0.25);
  EXPECT_EQ(ArgMin({3.0, 1.0, 2.0}), 1u);
  EXPECT_THROW(NormalizeByMax({0.0, 0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin
