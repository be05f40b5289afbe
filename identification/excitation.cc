#include "identification/excitation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/rng.h"
#include "core/units.h"
#include "model/leg_dynamics.h"
#include "model/regressors.h"

namespace exotwin {

namespace {

constexpr int kGrid = 2000;  // samples per period (200 Hz for f0 = 0.1 Hz)

double HeldAngle(IdConfiguration c) { return c == IdConfiguration::kKneeSwing ? M_PI / 2 : -M_PI / 2; }

// Joint state (q, qd, qdd) of both joints at sample i of one period.
void StateAt(const HarmonicTrajectory& tr, IdConfiguration c, int i, Eigen::Vector2d* q,
             Eigen::Vector2d* qd, Eigen::Vector2d* qdd) {
  const int m = c == IdConfiguration::kKneeSwing ? 1 : 0;
  double y, yd, ydd;
  tr.Eval(i / (kGrid * tr.f0), &y, &yd, &ydd);
  *q = Eigen::Vector2d::Constant(HeldAngle(c));
  *qd = Eigen::Vector2d::Zero();
  *qdd = Eigen::Vector2d::Zero();
  (*q)[m] = y;
  (*qd)[m] = yd;
  (*qdd)[m] = ydd;
}

}  // namespace

void HarmonicTrajectory::Eval(double t, double* q, double* qd, double* qdd) const {
  double p = q0, v = 0, acc = 0;
  for (size_t i = 0; i < k.size(); ++i) {
    const double w = 2.0 * M_PI * k[i] * f0;
    const double s = std::sin(w * t), c = std::cos(w * t);
    p += a[i] * s + b[i] * c;
    v += w * (a[i] * c - b[i] * s);
    acc += -w * w * (a[i] * s + b[i] * c);
  }
  *q = p;
  *qd = v;
  *qdd = acc;
}

JointLimits DefaultLimits(IdConfiguration c) {
  JointLimits l;
  if (c == IdConfiguration::kHipSwing) {
    l.q_min = 5 * kRadPerDeg;
    l.q_max = 40 * kRadPerDeg;
    l.qd_max = 120 * kRadPerDeg;
    l.tau_max = 100;
  } else {
    l.q_min = -70 * kRadPerDeg;
    l.q_max = -5 * kRadPerDeg;
    l.qd_max = 165 * kRadPerDeg;
    l.tau_max = 70;
  }
  return l;
}

HarmonicTrajectory FitToLimits(const HarmonicTrajectory& shape, const JointLimits& lim) {
  HarmonicTrajectory s = shape;
  s.q0 = 0;
  double lo = 1e300, hi = -1e300, vmax = 0;
  for (int i = 0; i < kGrid; ++i) {
    double q, qd, qdd;
    s.Eval(i / (kGrid * s.f0), &q, &qd, &qdd);
    lo = std::min(lo, q);
    hi = std::max(hi, q);
    vmax = std::max(vmax, std::abs(qd));
  }
  if (!(hi - lo > 1e-12)) throw InputError("excitation: constant trajectory shape, expected harmonics");
  double scale = (lim.q_max - lim.q_min) / (hi - lo);
  if (lim.qd_max > 0 && scale * vmax > lim.qd_max) scale = lim.qd_max / vmax;
  for (auto& v : s.a) v *= scale;
  for (auto& v : s.b) v *= scale;
  s.q0 = 0.5 * (lim.q_min + lim.q_max) - 0.5 * scale * (lo + hi);
  return s;
}

HarmonicTrajectory DefaultExcitation(IdConfiguration c, uint64_t seed) {
  HarmonicTrajectory s;
  s.f0 = 0.1;
  s.k = {3, 5, 8, 11, 15};
  Rng rng(seed);
  for (int k : s.k) {
    const double phase = 2.0 * M_PI * rng.Uniform();
    s.a.push_back(std::cos(phase) / k);
    s.b.push_back(std::sin(phase) / k);
  }
  return FitToLimits(s, DefaultLimits(c));
}

namespace {

// W'W of the step regressor over one period (held joint exactly held).
Eigen::Matrix3d RegressorGram(const HarmonicTrajectory& tr, IdConfiguration c, double L1, double g,
                              int stride = 1) {
  const bool knee = c == IdConfiguration::kKneeSwing;
  const int row = knee ? 1 : 0;
  const int cols[3] = {knee ? 1 : 0, knee ? 3 : 2, knee ? 5 : 4};
  Eigen::Matrix3d WtW = Eigen::Matrix3d::Zero();
  for (int i = 0; i < kGrid; i += stride) {
    Eigen::Vector2d q, qd, qdd;
    StateAt(tr, c, i, &q, &qd, &qdd);
    const Matrix26 Y = FullRegressor(L1, g, q, qd, qdd);
    const Eigen::Vector3d w(Y(row, cols[0]), Y(row, cols[1]), Y(row, cols[2]));
    WtW += w * w.transpose();
  }
  return WtW * stride;
}

double Condition(const Eigen::Matrix3d& WtW) {
  const Eigen::Vector3d d = WtW.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d S = d.asDiagonal() * WtW * d.asDiagonal();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvalues();
  return ev[0] > 0 ? std::sqrt(ev[2] / ev[0]) : 1e300;
}

double RelativeError(const Eigen::Matrix3d& WtW, IdConfiguration c, const LegParams& nominal) {
  const LumpedParams p = nominal.human ? *nominal.human : nominal.exo;  // the unknowns' system
  const bool knee = c == IdConfiguration::kKneeSwing;
  const Eigen::Vector3d tol(0.02 * std::abs(knee ? p.J2 : p.J1), 0.02 * std::abs(knee ? p.X2 : p.X1), 0.01);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(WtW);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return 1e300;
  const Eigen::Matrix3d inv = ldlt.solve(Eigen::Matrix3d::Identity());
  double sum = 0;
  for (int j = 0; j < 3; ++j) sum += std::max(0.0, inv(j, j)) / (tol[j] * tol[j]);
  return std::sqrt(sum / 3.0);
}

double Peak(const HarmonicTrajectory& tr, IdConfiguration c, const LegParams& nominal, int stride) {
  const int m = c == IdConfiguration::kKneeSwing ? 1 : 0;
  double peak = 0;
  for (int i = 0; i < kGrid; i += stride) {
    Eigen::Vector2d q, qd, qdd;
    StateAt(tr, c, i, &q, &qd, &qdd);
    peak = std::max(peak, std::abs(ActuatorTorque(nominal, q, qd, qdd)[m]));
  }
  return peak;
}

}  // namespace

double ExcitationRelativeError(const HarmonicTrajectory& tr, IdConfiguration c, const LegParams& nominal) {
  return RelativeError(RegressorGram(tr, c, nominal.L1, nominal.g), c, nominal);
}

double ExcitationCondition(const HarmonicTrajectory& tr, IdConfiguration c, double L1, double g) {
  return Condition(RegressorGram(tr, c, L1, g));
}

double PeakTorque(const HarmonicTrajectory& tr, IdConfiguration c, const LegParams& nominal) {
  return Peak(tr, c, nominal, 1);
}

ExcitationDesign DesignExcitation(IdConfiguration c, const ExcitationDesignOptions& opt) {
  const HarmonicTrajectory start = DefaultExcitation(c);
  const size_t nh = start.k.size();
  auto cost = [&](const HarmonicTrajectory& shape, HarmonicTrajectory* fitted) {
    double norm = 0;
    for (size_t i = 0; i < nh; ++i) norm += shape.a[i] * shape.a[i] + shape.b[i] * shape.b[i];
    if (!(norm > 1e-20)) return 1e300;
    // Search on a 50 Hz grid (>= 33 samples per cycle at 1.5 Hz) with a 2 % torque margin; the
    // result is re-checked on the full 200 Hz grid below.
    *fitted = FitToLimits(shape, opt.limits);
    if (opt.limits.tau_max > 0 && Peak(*fitted, c, opt.nominal, 4) > 0.98 * opt.limits.tau_max) return 1e300;
    const Eigen::Matrix3d WtW = RegressorGram(*fitted, c, opt.nominal.L1, opt.nominal.g, 4);
    return opt.criterion == ExcitationCriterion::kCondition ? Condition(WtW)
                                                            : RelativeError(WtW, c, opt.nominal);
  };
  ExcitationDesign out;
  HarmonicTrajectory best_fit;
  double best = cost(start, &best_fit);
  out.initial_condition = ExcitationCondition(DefaultExcitation(c), c, opt.nominal.L1, opt.nominal.g);
  NormalRng<NormalBoxMuller<BoxMullerU1::kMidpoint>> rng(opt.seed);
  for (int r = 0; r <= opt.restarts; ++r) {
    HarmonicTrajectory x = start;
    if (r > 0)
      for (size_t i = 0; i < nh; ++i) {
        x.a[i] = rng.Normal();
        x.b[i] = rng.Normal();
      }
    HarmonicTrajectory fx_traj;
    double fx = cost(x, &fx_traj);
    // Shapes are scale-free (FitToLimits rescales), so steps are relative to the shape's norm.
    double sigma = 0.3;
    for (int it = 0; it < opt.iterations; ++it) {
      double norm = 0;
      for (size_t i = 0; i < nh; ++i) norm += x.a[i] * x.a[i] + x.b[i] * x.b[i];
      norm = std::sqrt(norm / static_cast<double>(2 * nh));
      HarmonicTrajectory y = x;
      for (size_t i = 0; i < nh; ++i) {
        y.a[i] += sigma * norm * rng.Normal();
        y.b[i] += sigma * norm * rng.Normal();
      }
      HarmonicTrajectory fy_traj;
      const double fy = cost(y, &fy_traj);
      if (fy < fx) {
        x = y;
        fx = fy;
        fx_traj = fy_traj;
        sigma *= 1.5;
      } else {
        sigma *= 0.9;  // 1/5 success rule: 1.5 * 0.9^4 ~ 1
      }
      sigma = std::clamp(sigma, 1e-4, 2.0);
    }
    if (fx < best) {
      best = fx;
      best_fit = fx_traj;
    }
  }
  if (best < 1e299 && opt.limits.tau_max > 0 && PeakTorque(best_fit, c, opt.nominal) > opt.limits.tau_max)
    best = 1e300;  // the coarse search missed a peak (not seen in practice)
  if (!(best < 1e299))
    throw InputError("excitation design: no trajectory within the torque limit " +
                     std::to_string(opt.limits.tau_max) + " N m, expected a larger limit or range");
  out.trajectory = best_fit;
  out.condition = ExcitationCondition(best_fit, c, opt.nominal.L1, opt.nominal.g);
  out.relative_error = ExcitationRelativeError(best_fit, c, opt.nominal);
  out.initial_relative_error = ExcitationRelativeError(DefaultExcitation(c), c, opt.nominal);
  out.peak_torque = PeakTorque(best_fit, c, opt.nominal);
  for (int i = 0; i < kGrid; ++i) {
    double q, qd, qdd;
    best_fit.Eval(i / (kGrid * best_fit.f0), &q, &qd, &qdd);
    out.peak_speed = std::max(out.peak_speed, std::abs(qd));
  }
  return out;
}

}  // namespace exotwin
