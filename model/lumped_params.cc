#include "model/lumped_params.h"

namespace exotwin {

LumpedParams operator+(const LumpedParams& a, const LumpedParams& b) {
  LumpedParams s;
  s.J1 = a.J1 + b.J1;
  s.J2 = a.J2 + b.J2;
  s.X1 = a.X1 + b.X1;
  s.X2 = a.X2 + b.X2;
  s.Y1 = a.Y1 + b.Y1;
  s.Y2 = a.Y2 + b.Y2;
  return s;
}

const char* PassiveModelName(PassiveModel m) {
  return m == PassiveModel::kRiener1999 ? "riener1999" : "none";
}

LumpedParams LegParams::Total() const { return human ? exo + *human : exo; }

}  // namespace exotwin
