// Passive elastic joint torque P(q) of HJ15 eq. 1 and 12, rebuilt from Riener & Edrich 1999
// (J. Biomech. 32:539-544) because the 2015 print of HJ15 eq. 12 is garbled (see the .cc file).
#pragma once
#include <Eigen/Core>

#include "model/lumped_params.h"

namespace exotwin {

// Riener & Edrich 1999 hip moment (N m), positive in the direction of hip flexion.
// H hip flexion, K knee flexion (both degrees, K >= 0 flexed).
double RienerHipMoment(double H_deg, double K_deg);

// Riener & Edrich 1999 knee moment (N m), positive in the direction of knee flexion.
// A ankle plantarflexion, K knee flexion, H hip flexion (degrees).
double RienerKneeMoment(double A_deg, double K_deg, double H_deg);

// P(q) in this project's convention (q in rad, hip flexion positive, knee flexion negative), the term
// that sits on the left of HJ15 eq. 1 beside G: P = minus the passive moment along each generalized
// coordinate. Ankle held at 0 (the lower leg is one rigid segment). N m. kNone gives zero.
Eigen::Vector2d PassiveElasticTorque(PassiveModel model, const Eigen::Vector2d& q);

// P at q, q + h e_j and q - h e_j (a central difference's three points; j 0 hip, 1 knee; h rad) for
// many q with one j and h: each exponential of the laws at a shifted angle is its value at q times a
// constant factor exp(+-slope h), so 5 exponentials per q instead of 15. The point q is
// PassiveElasticTorque's bit for bit, the shifted ones to a few ulps of each term.
class PassiveNearPoints {
 public:
  PassiveNearPoints(PassiveModel model, int j, double h);
  void At(const Eigen::Vector2d& q, Eigen::Vector2d out[3]) const;

 private:
  PassiveModel model_;
  double up_[5], down_[5];  // the factors of the hip's two terms, then the knee's three
};

// A subject's passive moment as a multiple of Riener & Edrich's population curves lies in (0, this]:
// a stated bound (they and later studies report a wide spread between healthy subjects, none beyond
// a few times the mean curve); the emg loop's passive scale and the passive_moment effect share it.
constexpr double kMaxPassiveScale = 3.0;

}  // namespace exotwin
