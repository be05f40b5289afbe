// Identification regressors: the dynamics written linearly in the lumped parameters, HJ15 eq. 18-21
// and Appendix A1-A4 of Hwang & Jeon 2015, with the signs re-derived (see regressors.cc).
#pragma once
#include <Eigen/Core>

#include "model/lumped_params.h"

namespace exotwin {

using Matrix26 = Eigen::Matrix<double, 2, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// Parameter vector order of the full regressor: [J1, J2, X1, X2, Y1, Y2].
Vector6 ToVector(const LumpedParams& p);
LumpedParams FromVector(const Vector6& v);

// Full regressor Y(q, qd, qdd) with M qdd + V + G = Y * [J1 J2 X1 X2 Y1 Y2]^T, any state.
Matrix26 FullRegressor(double L1, double g, const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                       const Eigen::Vector2d& qdd);
// The sines and cosines of th1, th2 and th1 + th2 that FullRegressor uses.
struct RegressorTrig {
  double c2, s2, s1, c1, s12, c12;
};
RegressorTrig TrigOf(const Eigen::Vector2d& q);
// FullRegressor(L1, g, q, qd, qdd) with trig = TrigOf(q), the same numbers: for a caller that
// evaluates the regressor of one angle at several velocities.
// Defined here, inline: the per-sample loops that call it for every sample of a long record keep
// its entries in registers.
inline Matrix26 FullRegressorOfTrig(double L1, double g, const RegressorTrig& trig, const Eigen::Vector2d& qd,
                                    const Eigen::Vector2d& qdd) {
  const double c2 = trig.c2, s2 = trig.s2, s1 = trig.s1, c1 = trig.c1, s12 = trig.s12, c12 = trig.c12;
  const double a = 2.0 * qdd[0] + qdd[1];               // coefficient of h in row 1
  const double v = qd[1] * qd[1] + 2.0 * qd[0] * qd[1];  // Coriolis/centrifugal combination, row 1
  Matrix26 Y;
  // Row 1 (hip):  J1 q1'' + J2 q2'' + X2 [L1 c2 a - L1 s2 v + g s12] + Y2 [-L1 s2 a - L1 c2 v + g c12]
  //               + X1 g s1 + Y1 g c1
  Y(0, 0) = qdd[0];
  Y(0, 1) = qdd[1];
  Y(0, 2) = g * s1;
  Y(0, 3) = L1 * c2 * a - L1 * s2 * v + g * s12;
  Y(0, 4) = g * c1;
  Y(0, 5) = -L1 * s2 * a - L1 * c2 * v + g * c12;
  // Row 2 (knee): J2 (q1'' + q2'') + X2 [L1 c2 q1'' + L1 s2 q1'^2 + g s12]
  //               + Y2 [-L1 s2 q1'' + L1 c2 q1'^2 + g c12]
  Y(1, 0) = 0.0;
  Y(1, 1) = qdd[0] + qdd[1];
  Y(1, 2) = 0.0;
  Y(1, 3) = L1 * c2 * qdd[0] + L1 * s2 * qd[0] * qd[0] + g * s12;
  Y(1, 4) = 0.0;
  Y(1, 5) = -L1 * s2 * qdd[0] + L1 * c2 * qd[0] * qd[0] + g * c12;
  return Y;
}

// One row of a step regressor: u* = w^T phi (HJ15 eq. 18).
struct StepRow {
  double u_star = 0;
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
};

// Step 1 (exo R2, hip fixed at 90 deg, knee y moving): phi = [J_R2, X_R2, Y_R2]. u = tau_R knee.
StepRow Step1Row(double g, double y, double ydd, double u);
// Step 2 (exo R1, knee fixed at -90 deg, hip y moving): phi = [J_R1, X_R1, Y_R1]; needs X_R2, Y_R2.
StepRow Step2Row(double L1, double g, const LumpedParams& exo, double y, double ydd, double u);
// Step 3 (human H2, hip at 90 deg): phi = [J_H2, X_H2, Y_H2]; exo known; P2 the passive torque.
StepRow Step3Row(double g, const LumpedParams& exo, double y, double ydd, double u, double P2);
// Step 4 (human H1, knee at -90 deg): phi = [J_H1, X_H1, Y_H1]; exo and the human's X_H2, Y_H2
// (from step 3) known; P1 the passive torque.
StepRow Step4Row(double L1, double g, const LumpedParams& exo, const LumpedParams& human_distal,
                 double y, double ydd, double u, double P1);

}  // namespace exotwin
