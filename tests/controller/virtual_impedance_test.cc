// Tests of controller/virtual_impedance.h: with the compensation on, the exoskeleton link driven by an
// operator torque moves exactly like the virtual impedance (forward simulation of both), and Lee &
// Sankai's setting follows criteria (i)-(iii).
#include "controller/virtual_impedance.h"

#include <cmath>

#include <gtest/gtest.h>

namespace exotwin::controller {
namespace {

TEST(VirtualImpedance, LeeSankaiCriteria) {
  const OneLinkImpedance exo{0.06, 0.9, 1.8, 0.35};
  const VirtualImpedanceConfig c = LeeSankaiSetting(exo);
  EXPECT_EQ(c.target.I, 0.0);
  EXPECT_EQ(c.target.C, 0.0);
  EXPECT_EQ(c.target.mgl, exo.mgl);
  EXPECT_DOUBLE_EQ(c.target.B, 1.56);
  // Gravity retained: no gravity term in the compensation.
  EXPECT_NEAR(CompensationTorque(c, 0.7, 0, 0), 0.0, 1e-12);
}

TEST(VirtualImpedance, CompensatedLinkBehavesAsTheVirtualImpedance) {
  VirtualImpedanceConfig c;
  c.actual = {0.08, 0.9, 1.8, 0.35};
  c.target = {0.03, 1.56, 1.0, 0.1};
  // Real link with compensation (acceleration estimate = previous step's acceleration) vs the
  // virtual system, both driven by the same operator torque.
  double th = 0, thd = 0, thdd_prev = 0, tv = 0, tvd = 0;
  const double dt = 1e-4;
  double worst = 0;
  for (int k = 0; k < 50000; ++k) {
    const double t = k * dt, tau_op = 2.0 * std::sin(2 * M_PI * 0.5 * t) + 0.5;
    const double tau_c = CompensationTorque(c, th, thd, thdd_prev);
    const double sg = std::tanh(thd / c.coulomb_eps);
    const double thdd = (tau_op + tau_c - c.actual.B * thd - c.actual.mgl * std::sin(th) - c.actual.C * sg) /
                        c.actual.I;
    const double sv = std::tanh(tvd / c.coulomb_eps);
    const double tvdd = (tau_op - c.target.B * tvd - c.target.mgl * std::sin(tv) - c.target.C * sv) / c.target.I;
    thd += dt * thdd;
    th += dt * thd;
    tvd += dt * tvdd;
    tv += dt * tvd;
    thdd_prev = thdd;
    worst = std::max(worst, std::abs(th - tv));
  }
  EXPECT_LT(worst, 0.01);  // rad, over 5 s
  // The felt torque is the virtual impedance when the acceleration is known.
  EXPECT_NEAR(FeltImpedanceTorque(c, 0.4, 1.2, -3.0),
              c.target.I * -3.0 + c.target.B * 1.2 + c.target.mgl * std::sin(0.4) +
                  c.target.C * std::tanh(1.2 / c.coulomb_eps),
              1e-12);
}

}  // namespace
}  // namespace exotwin::controller
