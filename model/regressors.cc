#include "model/regressors.h"

#include <cmath>

namespace exotwin {

// Sign question of HJ15 eq. 15, 17, A2, A4. From HJ15 eq. 5, M11 = J1 + 2 L1 (X2 cos th2 - Y2 sin th2).
// With the knee held at th2 = -90 deg: cos th2 = 0, sin th2 = -1, so M11 = J1 + 2 L1 Y2, not the
// printed "J1 - 2 L1 Y2". The gravity term, with th12 = th1 - 90 deg (sin th12 = -cos th1,
// cos th12 = sin th1), is g (X1 sin th1 + Y1 cos th1 - X2 cos th1 + Y2 sin th1) as printed, and the
// Coriolis term vanishes (th2d = 0). Hence
//   step 2: u2 = (J_R1 + 2 L1 Y_R2) y'' + g (X_R1 sin y + Y_R1 cos y - X_R2 cos y + Y_R2 sin y)
//   step 4: u4 = (J_RH1 + 2 L1 Y_RH2) y'' + g (...RH...) + P1.
// With the hip held at th1 = 90 deg (sin th12 = cos th2, cos th12 = -sin th2), the knee row is
//   u1 = J_R2 y'' + g (X_R2 cos y - Y_R2 sin y)           (LS05 eq. 14 as printed)
// so w1 = [y'', g cos y, -g sin y]: (A1) prints "+g sin y", another sign slip. (A3) moves the known
// exo part with the wrong sign ("+J_R2 y''"); u3* = u3 - P2 - J_R2 y'' - g (X_R2 cos y - Y_R2 sin y).
// tests/model/regressors_test.cc checks all four rows against MuJoCo and the closed form.

Vector6 ToVector(const LumpedParams& p) {
  Vector6 v;
  v << p.J1, p.J2, p.X1, p.X2, p.Y1, p.Y2;
  return v;
}

LumpedParams FromVector(const Vector6& v) {
  LumpedParams p;
  p.J1 = v[0];
  p.J2 = v[1];
  p.X1 = v[2];
  p.X2 = v[3];
  p.Y1 = v[4];
  p.Y2 = v[5];
  return p;
}

RegressorTrig TrigOf(const Eigen::Vector2d& q) {
  RegressorTrig r;
  r.c2 = std::cos(q[1]), r.s2 = std::sin(q[1]);
  r.s1 = std::sin(q[0]), r.c1 = std::cos(q[0]);
  r.s12 = std::sin(q[0] + q[1]), r.c12 = std::cos(q[0] + q[1]);
  return r;
}

Matrix26 FullRegressor(double L1, double g, const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                       const Eigen::Vector2d& qdd) {
  return FullRegressorOfTrig(L1, g, TrigOf(q), qd, qdd);
}

StepRow Step1Row(double g, double y, double ydd, double u) {
  StepRow r;
  r.u_star = u;
  r.w << ydd, g * std::cos(y), -g * std::sin(y);
  return r;
}

StepRow Step2Row(double L1, double g, const LumpedParams& exo, double y, double ydd, double u) {
  StepRow r;
  r.u_star = u - 2.0 * L1 * exo.Y2 * ydd - g * (-exo.X2 * std::cos(y) + exo.Y2 * std::sin(y));
  r.w << ydd, g * std::sin(y), g * std::cos(y);
  return r;
}

StepRow Step3Row(double g, const LumpedParams& exo, double y, double ydd, double u, double P2) {
  StepRow r;
  r.u_star = u - P2 - exo.J2 * ydd - g * (exo.X2 * std::cos(y) - exo.Y2 * std::sin(y));
  r.w << ydd, g * std::cos(y), -g * std::sin(y);
  return r;
}

StepRow Step4Row(double L1, double g, const LumpedParams& exo, const LumpedParams& human_distal,
                 double y, double ydd, double u, double P1) {
  const double X_RH2 = exo.X2 + human_distal.X2;
  const double Y_RH2 = exo.Y2 + human_distal.Y2;
  StepRow r;
  r.u_star = u - P1 - (exo.J1 + 2.0 * L1 * Y_RH2) * ydd -
             g * (exo.X1 * std::sin(y) + exo.Y1 * std::cos(y) - X_RH2 * std::cos(y) +
                  Y_RH2 * std::sin(y));
  r.w << ydd, g * std::sin(y), g * std::cos(y);
  return r;
}

}  // namespace exotwin
