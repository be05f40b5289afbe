// Virtual impedance compensation (Lee & Sankai): see virtual_impedance.h.
#include "controller/virtual_impedance.h"

#include <cmath>

namespace exotwin::controller {

VirtualImpedanceConfig LeeSankaiSetting(const OneLinkImpedance& actual, double b_v) {
  VirtualImpedanceConfig c;
  c.actual = actual;
  c.target.I = 0;             // criterion (i)
  c.target.C = 0;             // criterion (i)
  c.target.mgl = actual.mgl;  // criterion (ii)
  c.target.B = b_v;           // criterion (iii)
  return c;
}

double CompensationTorque(const VirtualImpedanceConfig& c, double th, double thd, double thdd) {
  const double sgn = std::tanh(thd / c.coulomb_eps);
  return (c.actual.I - c.target.I) * thdd + (c.actual.B - c.target.B) * thd +
         (c.actual.mgl - c.target.mgl) * std::sin(th) + (c.actual.C - c.target.C) * sgn;
}

double FeltImpedanceTorque(const VirtualImpedanceConfig& c, double th, double thd, double thdd) {
  const double sgn = std::tanh(thd / c.coulomb_eps);
  const double exo = c.actual.I * thdd + c.actual.B * thd + c.actual.mgl * std::sin(th) + c.actual.C * sgn;
  return exo - CompensationTorque(c, th, thd, thdd);
}

}  // namespace exotwin::controller
