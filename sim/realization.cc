#include "sim/realization.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace exotwin {

// Given m2 > 0: a2 = X2/m2, b2 = Y2/m2, Iz2 = J2 - (X2^2 + Y2^2)/m2 > 0  <=>  m2 > (X2^2 + Y2^2)/J2.
// Given m1 > 0: m1 a1 = X1 - m2 L1, b1 = Y1/m1,
//   Iz1 = J1 - J2 - m2 L1^2 - ((X1 - m2 L1)^2 + Y1^2)/m1 > 0
//   <=>  J1 - J2 - m2 L1^2 > 0 (m2 < (J1 - J2)/L1^2) and m1 > ((X1 - m2 L1)^2 + Y1^2)/(J1 - J2 - m2 L1^2).
// So a realization exists iff J2 > 0 and (X2^2 + Y2^2)/J2 < (J1 - J2)/L1^2.
SystemRealization RealizeLumped(const LumpedParams& p, double L1, const std::string& what) {
  auto fail = [&](const std::string& why) {
    throw InputError(what + ": lumped parameters have no physically consistent realization (" + why +
                     ")");
  };
  for (double v : {p.J1, p.J2, p.X1, p.X2, p.Y1, p.Y2, p.m1, p.m2, L1})
    if (!std::isfinite(v)) fail("a value is not finite");
  if (!(L1 > 0)) fail("L1 must be > 0");
  if (p.m1 < 0) fail("m1 must be >= 0 (0 = choose), got " + std::to_string(p.m1));
  if (p.m2 < 0) fail("m2 must be >= 0 (0 = choose), got " + std::to_string(p.m2));
  if (!(p.J2 > 0)) fail("J2 must be > 0, got " + std::to_string(p.J2));
  const double lo2 = (p.X2 * p.X2 + p.Y2 * p.Y2) / p.J2;
  const double hi2 = (p.J1 - p.J2) / (L1 * L1);
  if (!(hi2 > lo2)) {
    std::ostringstream os;
    os << "needs (X2^2+Y2^2)/J2 < (J1-J2)/L1^2, got " << lo2 << " >= " << hi2
       << " kg; J1 too small for J2, X2, Y2 and L1";
    fail(os.str());
  }
  double m2 = p.m2 > 0 ? p.m2 : 0.5 * (lo2 + hi2);
  if (!(m2 > lo2 && m2 < hi2)) {
    std::ostringstream os;
    os << "m2 = " << m2 << " kg outside its feasible window (" << lo2 << ", " << hi2 << ")";
    fail(os.str());
  }
  const double den = p.J1 - p.J2 - m2 * L1 * L1;
  const double mx = p.X1 - m2 * L1;
  const double lo1 = (mx * mx + p.Y1 * p.Y1) / den;
  double m1 = p.m1 > 0 ? p.m1 : std::max(1.25 * lo1, 1e-3);
  if (!(m1 > lo1)) {
    std::ostringstream os;
    os << "m1 = " << m1 << " kg below its lower bound " << lo1 << " kg";
    fail(os.str());
  }
  SystemRealization r;
  r.lower_leg.mass = m2;
  r.lower_leg.a = p.X2 / m2;
  r.lower_leg.b = p.Y2 / m2;
  r.lower_leg.Iz = p.J2 - (p.X2 * p.X2 + p.Y2 * p.Y2) / m2;
  r.thigh.mass = m1;
  r.thigh.a = mx / m1;
  r.thigh.b = p.Y1 / m1;
  r.thigh.Iz = den - (mx * mx + p.Y1 * p.Y1) / m1;
  return r;
}

LumpedParams LumpRealization(const SystemRealization& r, double L1) {
  const SegmentInertial& s1 = r.thigh;
  const SegmentInertial& s2 = r.lower_leg;
  LumpedParams p;
  p.J2 = s2.Iz + s2.mass * (s2.a * s2.a + s2.b * s2.b);
  p.J1 = s1.Iz + s1.mass * (s1.a * s1.a + s1.b * s1.b) + p.J2 + s2.mass * L1 * L1;
  p.X1 = s1.mass * s1.a + s2.mass * L1;
  p.X2 = s2.mass * s2.a;
  p.Y1 = s1.mass * s1.b;
  p.Y2 = s2.mass * s2.b;
  p.m1 = s1.mass;
  p.m2 = s2.mass;
  return p;
}

}  // namespace exotwin
