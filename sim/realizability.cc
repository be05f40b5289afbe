#include "sim/realizability.h"

#include <cmath>
#include <sstream>

namespace exotwin {

// Derivation (HJ15 eq. 4). Lower leg: a2 = X2/m2, b2 = Y2/m2, Iz2 = J2 - (X2^2 + Y2^2)/m2 > 0
//   <=> m2 > (X2^2 + Y2^2)/J2 (needs J2 > 0).
// Thigh: m1 a1 = X1 - m2 L1, m1 b1 = Y1,
//   Iz1 = J1 - J2 - m2 L1^2 - ((X1 - m2 L1)^2 + Y1^2)/m1 > 0
//   <=> m2 < (J1 - J2)/L1^2 and m1 > ((X1 - m2 L1)^2 + Y1^2)/(J1 - J2 - m2 L1^2), always satisfiable.
bool IsRealizable(const LumpedParams& p, double L1, std::string* why) {
  auto fail = [why](const std::string& msg) {
    if (why) *why = msg;
    return false;
  };
  for (double v : {p.J1, p.J2, p.X1, p.X2, p.Y1, p.Y2, L1})
    if (!std::isfinite(v)) return fail("a lumped parameter or L1 is not finite");
  if (!(L1 > 0)) return fail("L1 must be > 0 m");
  if (!(p.J2 > 0)) {
    std::ostringstream os;
    os << "J2 = " << p.J2 << " kg m^2, must be > 0";
    return fail(os.str());
  }
  const double m2_lo = (p.X2 * p.X2 + p.Y2 * p.Y2) / p.J2;
  const double m2_hi = (p.J1 - p.J2) / (L1 * L1);
  if (!(m2_hi > m2_lo)) {
    std::ostringstream os;
    os << "no lower-leg mass fits: needs (X2^2+Y2^2)/J2 < (J1-J2)/L1^2, got " << m2_lo
       << " kg >= " << m2_hi << " kg (J1 too small for J2, X2, Y2 and L1)";
    return fail(os.str());
  }
  if (why) why->clear();
  return true;
}

}  // namespace exotwin
