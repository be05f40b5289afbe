#include "model/passive_torque.h"

#include <cmath>

#include "core/units.h"

namespace exotwin {

// The original law (Riener & Edrich 1999), angles in degrees, each moment positive in the direction of
// its angle (hip flexion, knee flexion, ankle plantarflexion):
//   M_H = exp(1.4655 - 0.0034 K - 0.0750 H) - exp(1.3403 - 0.0226 K + 0.0305 H) + 8.072
//   M_K = exp(1.800 - 0.0460 A - 0.0352 K + 0.0217 H) - exp(-3.971 - 0.0004 A + 0.0495 K - 0.0128 H)
//         + exp(2.220 - 0.150 K) - 4.820
// HJ15 eq. 12 of Hwang & Jeon 2015 converted these to radians as if th2 were flexion-positive (it is
// flexion-negative), flipped P2's overall sign and mixed the coefficients of the second knee
// exponential (its "0.73 th2 - 0.0128 th1" should read "-2.836 th2 - 0.733 th1" in its own
// convention). We do not use HJ15 eq. 12: we map the conventions explicitly,
//   H = deg(th1),  K = -deg(th2),  A = 0,
// and, since the moment M_H acts along +th1 and M_K along -th2 (knee flexion = negative th2),
//   P1 = -M_H,  P2 = -(-M_K) = +M_K.
namespace {

// The laws above as sums of terms sign * exp(a + cA A + cK K + cH H) plus a constant, evaluated in the
// order written (each coefficient's sign carried into it: x - c y and x + (-c) y are the same double).
struct ExpTerm {
  double sign, a, cA, cK, cH;
};
constexpr ExpTerm kHipTerms[] = {{1, 1.4655, 0, -0.0034, -0.0750}, {-1, 1.3403, 0, -0.0226, 0.0305}};
constexpr double kHipConstant = 8.072;
constexpr ExpTerm kKneeTerms[] = {
    {1, 1.800, -0.0460, -0.0352, 0.0217}, {-1, -3.971, -0.0004, 0.0495, -0.0128}, {1, 2.220, 0, -0.150, 0}};
constexpr double kKneeConstant = -4.820;

double Exponent(const ExpTerm& e, double A, double K, double H) { return e.a + e.cA * A + e.cK * K + e.cH * H; }

// The moment from its terms' exponentials e[i], summed in the order written.
template <size_t N>
double Sum(const ExpTerm (&terms)[N], double constant, const double* e) {
  double m = terms[0].sign * e[0];
  for (size_t i = 1; i < N; ++i) m += terms[i].sign * e[i];
  return m + constant;
}

template <size_t N>
double Moment(const ExpTerm (&terms)[N], double constant, double A, double K, double H) {
  double e[N];
  for (size_t i = 0; i < N; ++i) e[i] = std::exp(Exponent(terms[i], A, K, H));
  return Sum(terms, constant, e);
}

}  // namespace

double RienerHipMoment(double H, double K) { return Moment(kHipTerms, kHipConstant, 0.0, K, H); }

double RienerKneeMoment(double A, double K, double H) { return Moment(kKneeTerms, kKneeConstant, A, K, H); }

Eigen::Vector2d PassiveElasticTorque(PassiveModel model, const Eigen::Vector2d& q) {
  if (model == PassiveModel::kNone) return Eigen::Vector2d::Zero();
  const double H = q[0] * kDegPerRad;
  const double K = -q[1] * kDegPerRad;
  return Eigen::Vector2d(-RienerHipMoment(H, K), RienerKneeMoment(0.0, K, H));
}

PassiveNearPoints::PassiveNearPoints(PassiveModel model, int j, double h) : model_(model) {
  // q_j + h moves H by +h deg (hip) or K by -h deg (knee): term i's exponent by slope_i h.
  auto slope = [&](const ExpTerm& e) { return j == 0 ? e.cH * kDegPerRad : -e.cK * kDegPerRad; };
  for (size_t i = 0; i < 2; ++i) up_[i] = std::exp(slope(kHipTerms[i]) * h), down_[i] = std::exp(-slope(kHipTerms[i]) * h);
  for (size_t i = 0; i < 3; ++i)
    up_[2 + i] = std::exp(slope(kKneeTerms[i]) * h), down_[2 + i] = std::exp(-slope(kKneeTerms[i]) * h);
}

void PassiveNearPoints::At(const Eigen::Vector2d& q, Eigen::Vector2d out[3]) const {
  if (model_ == PassiveModel::kNone) {
    out[0] = out[1] = out[2] = Eigen::Vector2d::Zero();
    return;
  }
  const double H = q[0] * kDegPerRad, K = -q[1] * kDegPerRad;
  double e[5];
  for (size_t i = 0; i < 2; ++i) e[i] = std::exp(Exponent(kHipTerms[i], 0.0, K, H));
  for (size_t i = 0; i < 3; ++i) e[2 + i] = std::exp(Exponent(kKneeTerms[i], 0.0, K, H));
  for (int k = 0; k < 3; ++k) {
    const double* f = k == 1 ? up_ : down_;
    double x[5];
    for (int i = 0; i < 5; ++i) x[i] = k == 0 ? e[i] : e[i] * f[i];
    out[k] = Eigen::Vector2d(-Sum(kHipTerms, kHipConstant, x), Sum(kKneeTerms, kKneeConstant, x + 2));
  }
}

}  // namespace exotwin
