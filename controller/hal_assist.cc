// HAL assist control (Hayashi, Kawamoto & Sankai): see hal_assist.h.
#include "controller/hal_assist.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "dsp/derivatives.h"

namespace exotwin::controller {

LinearFit FitEmgToTorque(const std::vector<double>& E, const std::vector<double>& tau) {
  if (E.size() != tau.size() || E.size() < 2) throw std::invalid_argument("FitEmgToTorque: sizes");
  double mt = 0, me = 0;
  for (size_t k = 0; k < E.size(); ++k) mt += tau[k], me += E[k];
  mt /= E.size();
  me /= E.size();
  double stt = 0, ste = 0;
  for (size_t k = 0; k < E.size(); ++k) {
    stt += (tau[k] - mt) * (tau[k] - mt);
    ste += (tau[k] - mt) * (E[k] - me);
  }
  if (!(stt > 0)) throw std::invalid_argument("FitEmgToTorque: the calibration torque is constant");
  const double c = ste / stt;  // V per N m: E = c tau + d
  if (!(c > 0)) throw std::invalid_argument("FitEmgToTorque: the envelope does not grow with the torque");
  LinearFit f;
  f.a = 1.0 / c;
  f.b = mt - f.a * me;  // the inverted line passes through the means: b = -d / c
  return f;
}

double NoiseCorrectedEnvelope(double E, double E0) {
  if (!(E0 > 0)) return E;
  return std::sqrt(std::max(E * E - E0 * E0, 0.0));
}

double EstimateMuscleTorque(const HalEmgCoefficients& c, double E_e, double E_f) {
  const double Ee = NoiseCorrectedEnvelope(E_e, c.baseline_e), Ef = NoiseCorrectedEnvelope(E_f, c.baseline_f);
  return (c.extensor.a * Ee + c.extensor.b) - (c.flexor.a * Ef + c.flexor.b);  // HKS05 eq. 2
}

OneLinkPassive IdentifyOneLinkPassive(const std::vector<double>& th, const std::vector<double>& tau,
                                      double dt, double fc) {
  if (th.size() != tau.size() || th.size() < 16 || !(dt > 0))
    throw std::invalid_argument("IdentifyOneLinkPassive: sizes or dt");
  const dsp::Derivatives d = dsp::ZeroPhaseDerivatives(th, dt, fc);
  const std::vector<double>& f = d.filtered;
  const std::vector<double>& v = d.first;
  const std::vector<double>& a = d.second;
  const size_t skip = std::min<size_t>(th.size() / 8, 50);  // filter edges
  const size_t n = th.size() - 2 * skip;
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t k = i + skip;
    A(i, 0) = a[k];
    A(i, 1) = v[k];
    A(i, 2) = std::sin(f[k]);
    b[i] = tau[k];
  }
  const Eigen::Vector3d x = A.colPivHouseholderQr().solve(b);  // HKS05 eq. 14/15
  return {x[0], x[1], x[2]};
}

double GravityStiffness(double mgl, double th) {
  return std::abs(th) < 1e-9 ? mgl : mgl * std::sin(th) / th;  // HKS05 eq. 8
}

ViscoelasticRls::ViscoelasticRls(const ViscoelasticRlsConfig& cfg) : cfg_(cfg) {
  if (!(cfg.dt > 0) || !(cfg.rho > 0 && cfg.rho <= 1) || !(cfg.p0 > 0) || !(cfg.pf > 0) ||
      !(cfg.I0 > 0))
    throw std::invalid_argument("ViscoelasticRls: need dt > 0, 0 < rho <= 1, p0 > 0, pf > 0, I0 > 0");
  e1_ = 2 * cfg.pf;
  e2_ = cfg.pf * cfg.pf;
  // X = [e1 - D'/I, e2 - K'/I, T/(2I), 1/I], HKS05 eq. 11, from the prior (K' at th = 0).
  const double Dp = cfg.D0 + cfg.R, Kp = cfg.K0 + (cfg.gravity_in_input ? 0.0 : cfg.mgl);
  X_ << e1_ - Dp / cfg.I0, e2_ - Kp / cfg.I0, cfg.dt / (2 * cfg.I0), 1 / cfg.I0;
  P_ = cfg.p0 * Eigen::Matrix4d::Identity();
  // Known inertia: X3, X4 have zero covariance, so P phi has no X3, X4 component and HKS05 eq. 13 is
  // the two-parameter RLS on th - X3 phi3 - X4 phi4 (its rows and columns stay zero under HKS05 eq. 13).
  if (cfg.known_inertia) P_.block<2, 2>(2, 2).setZero();
}

void ViscoelasticRls::Step(double th, double u_in) {
  const double u = cfg_.gravity_in_input ? u_in - cfg_.mgl * std::sin(th) : u_in;
  // Regressor phi(k) = [d th/E, th/E, d u/E, u/E] (HKS05 eq. 11) from the filter states at k.
  const Eigen::Vector4d phi(s2t_, s1t_, s2u_, s1u_);
  err_ = th - phi.dot(X_);  // HKS05 eq. 12
  const Eigen::Vector4d Pphi = P_ * phi;
  const double den = cfg_.rho + phi.dot(Pphi);
  X_ += Pphi * (err_ / den);                              // HKS05 eq. 13
  P_ = (P_ - Pphi * Pphi.transpose() / den) / cfg_.rho;   // HKS05 eq. 13, forgetting factor rho
  // The paper prints P(k+1) = (P - P phi phi' P)/(rho + phi' P phi): a typo for the standard
  // exponentially weighted RLS used here (the printed form does not forget).
  P_ = 0.5 * (P_ + P_.transpose());                        // keep symmetric
  const double tr = P_.trace();
  if (tr > cfg_.p_max) P_ *= cfg_.p_max / tr;              // anti-windup
  // Advance the state-variable filters 1/E(delta) (delta = forward difference / T).
  const double T = cfg_.dt;
  const double n2t = s2t_ + T * (th - e1_ * s2t_ - e2_ * s1t_);
  s1t_ += T * s2t_;
  s2t_ = n2t;
  const double n2u = s2u_ + T * (u - e1_ * s2u_ - e2_ * s1u_);
  s1u_ += T * s2u_;
  s2u_ = n2u;
  th_last_ = th;
}

double ViscoelasticRls::I() const { return 1.0 / X_[3]; }
double ViscoelasticRls::Dprime() const { return (e1_ - X_[0]) * I(); }
double ViscoelasticRls::Kprime() const { return (e2_ - X_[1]) * I(); }
double ViscoelasticRls::K() const {
  return cfg_.gravity_in_input ? Kprime() : Kprime() - GravityStiffness(cfg_.mgl, th_last_);
}

AdaptiveObserver::AdaptiveObserver(double dt, double lambda1, double lambda2)
    : dt_(dt), l1_(lambda1), l2_(lambda2) {
  if (!(dt > 0) || !(lambda1 > 0) || !(lambda2 > 0))
    throw std::invalid_argument("AdaptiveObserver: dt, lambda1, lambda2 must be > 0");
}

void AdaptiveObserver::Step(double th, double u, double I, double Dp, double Kp) {
  const double a1 = Dp / I, a0 = Kp / I;
  const double g1 = l1_ + l2_ - a1;           // HKS05 eq. 17, re-derived (see header)
  const double g2 = l1_ * l2_ - a0 - g1 * a1;
  const double b1 = dt_ / (2 * I), b2 = (1 - Dp * dt_ / (2 * I)) / I;  // HKS05 eq. 10
  const double e = th - x1_;
  const double d1 = x2_ + b1 * u + g1 * e;                 // HKS05 eq. 16
  const double d2 = -a0 * x1_ - a1 * x2_ + b2 * u + g2 * e;
  x1_ += dt_ * d1;
  x2_ += dt_ * d2;
}

HalAssistController::HalAssistController(const HalAssistConfig& cfg)
    : cfg_(cfg), rls_(cfg.rls), obs_(cfg.dt, cfg.lambda1, cfg.lambda2) {}

HalAssistOutput HalAssistController::Step(double th, double E_e, double E_f, double tau_c) {
  HalAssistOutput o;
  if (!started_) {
    obs_.Reset(th);
    started_ = true;
  }
  o.mu_hat = EstimateMuscleTorque(cfg_.emg, E_e, E_f);     // HKS05 eq. 2
  // HKS05 eq. 9, sigma = 0; minus the actuator's known Coulomb friction (friction_C, our extension).
  const double u = tau_prev_ + o.mu_hat - cfg_.friction_C * std::tanh(thd_prev_ / cfg_.friction_eps);
  rls_.Step(th, u);
  // Safety (our addition): estimates outside a physical range (I beyond 1/4..4 x the identified
  // I0, negative or non-finite D, K) are replaced by the clamped / prior values, so a badly excited
  // RLS cannot drive the observer or the actuator to NaN.
  const ViscoelasticRlsConfig& rc = cfg_.rls;
  const auto finite_or = [](double v, double fallback) { return std::isfinite(v) ? v : fallback; };
  const double I = std::clamp(finite_or(rls_.I(), rc.I0), 0.25 * rc.I0, 4.0 * rc.I0);
  o.D = std::max(0.0, finite_or(rls_.D(), rc.D0));
  o.K = std::max(0.0, finite_or(rls_.K(), rc.K0));
  // The observer uses the paper's linear model (9): D' = D + R, K' = K + G(th).
  obs_.Step(th, u, I, o.D + rc.R, o.K + GravityStiffness(rc.mgl, th));
  o.thd_hat = obs_.velocity();
  if (!std::isfinite(o.thd_hat)) {
    obs_.Reset(th);
    o.thd_hat = 0;
  }
  o.tau_mu = cfg_.alpha_mu * o.mu_hat;                      // HKS05 eq. 3
  o.tau_zeta = cfg_.alpha_zeta * (-o.D * o.thd_hat - o.K * th);  // HKS05 eq. 5
  o.tau_c = tau_c;
  o.tau = std::clamp(o.tau_zeta + o.tau_mu + o.tau_c, -cfg_.tau_max, cfg_.tau_max);  // HKS05 eq. 6
  tau_prev_ = o.tau;
  thd_prev_ = o.thd_hat;
  return o;
}

}  // namespace exotwin::controller
