#include "model/leg_dynamics.h"

#include <cmath>

#include "model/passive_torque.h"

namespace exotwin {

// Derivation (kept here because the paper's later equations get signs wrong, see regressors.cc).
// Plane with x forward, y up. Thigh direction u1 = (sin th1, -cos th1); the perpendicular
// n1 = (cos th1, sin th1) is u1 turned by +90 deg. Segment i's centre of mass is a_i u_i + b_i n_i
// from its proximal joint, with u2, n2 at th12 = th1 + th2 and the knee at L1 u1.
//   Potential energy: y_c1 = -a1 cos th1 + b1 sin th1, y_c2 = -L1 cos th1 - a2 cos th12 + b2 sin th12
//   => G = dV/dq gives HJ15 eq. 7: G1 = g (X1 s1 + Y1 c1 + X2 s12 + Y2 c12), G2 = g (X2 s12 + Y2 c12).
//   Kinetic energy cross term of segment 2: m2 L1 th1d th12d (a2 cos th2 - b2 sin th2)
//   => HJ15 eq. 5: M11 = J1 + 2 L1 (X2 c2 - Y2 s2), M12 = J2 + L1 (X2 c2 - Y2 s2), M22 = J2,
//   and the Christoffel terms of HJ15 eq. 6.
Eigen::Matrix2d MassMatrix(const LumpedParams& p, double L1, double th2) {
  const double h = L1 * (p.X2 * std::cos(th2) - p.Y2 * std::sin(th2));
  Eigen::Matrix2d M;
  M << p.J1 + 2.0 * h, p.J2 + h, p.J2 + h, p.J2;
  return M;
}

Vec2 CoriolisCentrifugal(const LumpedParams& p, double L1, const Vec2& q, const Vec2& qd) {
  const double k = L1 * (p.X2 * std::sin(q[1]) + p.Y2 * std::cos(q[1]));  // = -dh/dth2
  return Vec2(-k * (qd[1] * qd[1] + 2.0 * qd[0] * qd[1]), k * qd[0] * qd[0]);
}

Vec2 GravityTorque(const LumpedParams& p, double g, const Vec2& q) {
  const double th12 = q[0] + q[1];
  const double G2 = g * (p.X2 * std::sin(th12) + p.Y2 * std::cos(th12));
  return Vec2(g * (p.X1 * std::sin(q[0]) + p.Y1 * std::cos(q[0])) + G2, G2);
}

Vec2 RigidInverseDynamics(const LumpedParams& p, double L1, double g, const Vec2& q, const Vec2& qd,
                          const Vec2& qdd) {
  return MassMatrix(p, L1, q[1]) * qdd + CoriolisCentrifugal(p, L1, q, qd) + GravityTorque(p, g, q);
}

Vec2 ActuatorTorque(const LegParams& params, const Vec2& q, const Vec2& qd, const Vec2& qdd) {
  Vec2 tau = RigidInverseDynamics(params.Total(), params.L1, params.g, q, qd, qdd);
  if (params.human) tau += PassiveElasticTorque(params.passive, q);
  return tau;
}

double MechanicalEnergy(const LumpedParams& p, double L1, double g, const Vec2& q, const Vec2& qd) {
  const double T = 0.5 * qd.dot(MassMatrix(p, L1, q[1]) * qd);
  const double th12 = q[0] + q[1];
  const double V = -g * (p.X1 * std::cos(q[0]) - p.Y1 * std::sin(q[0]) + p.X2 * std::cos(th12) -
                         p.Y2 * std::sin(th12));
  return T + V;
}

}  // namespace exotwin
