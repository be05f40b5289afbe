// Tests of dsp/mvc.h: the MVC of trial windows is the mean of the windows' peaks, computed by hand.
#include "dsp/mvc.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace exotwin::dsp {
namespace {

TEST(Mvc, MeanOfTheTrialPeaksAndNormalization) {
  std::vector<double> env(12000, 0.01);
  const double levels[] = {0.50, 0.60, 0.55, 0.20};
  for (int trial = 0; trial < 4; ++trial)
    for (int k = 0; k <= 1000; ++k) env[1000 + trial * 2500 + k] = levels[trial] * std::sin(M_PI * k / 1000.0);
  // Three windows around the first three half-sines: peaks 0.50, 0.60, 0.55 at their centres.
  const std::vector<std::pair<size_t, size_t>> w = {{900, 2200}, {3400, 4700}, {5900, 7200}};
  EXPECT_DOUBLE_EQ(MvcOfTrials(env, w), (0.5 + 0.6 + 0.55) / 3);
  // A window of the relaxed level only.
  EXPECT_DOUBLE_EQ(MvcOfTrials(env, {{0, 900}}), 0.01);
  EXPECT_DOUBLE_EQ(NormalizeToMvc(0.6, 0.0, 0.55), 0.6 / 0.55);
  EXPECT_DOUBLE_EQ(NormalizeToMvc(0.6, 0.1, 0.55), 0.5 / 0.45);
  EXPECT_DOUBLE_EQ(NormalizeToMvc(0.1, 0.1, 0.55), 0.0);  // the relaxed level reads 0 % MVC
}

TEST(Mvc, RejectsMissingOrBadWindows) {
  const std::vector<double> env(100, 1.0);
  EXPECT_THROW(MvcOfTrials(env, {}), std::invalid_argument);
  EXPECT_THROW(MvcOfTrials(env, {{10, 10}}), std::invalid_argument);   // empty
  EXPECT_THROW(MvcOfTrials(env, {{50, 101}}), std::invalid_argument);  // past the end
}

}  // namespace
}  // namespace exotwin::dsp
