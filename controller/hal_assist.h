// HAL assist control of Hayashi, Kawamoto & Sankai ("Control method of robot suit HAL working as
// operator's muscle using biological and dynamical information"), issue 6 item 6. One knee joint in
// HAL's convention: th = 0 lower leg hanging, positive = extension (th = th2 + pi/2 seated).
//   muscle torque estimate  mu^ = (a_e E_e + b_e) - (a_f E_f + b_f)          HKS05 eq. 2
//   tau_mu = alpha_mu mu^                                                   HKS05 eq. 3
//   one-link model  I thdd + (D + R) thd + K th + Mgl sin th = tau + mu      HKS05 eq. 4
//   tau_zeta = alpha_zeta (-D thd - K th)                                   HKS05 eq. 5
//   tau = tau_zeta + tau_mu + tau_c                                         HKS05 eq. 6
//   on-line D, K: delta-operator model + recursive weighted least squares    HKS05 eq. 8-13
//   passive parameters identified first                                     HKS05 eq. 14-15
//   state observer with adaptive gains                                      HKS05 eq. 16-17
// Units: N m, rad, rad/s, s; E in V (amplified RMS envelope, HKS05 eq. 1).
#pragma once
#include <vector>

#include <Eigen/Core>

namespace exotwin::controller {

// Straight line y = a x + b.
struct LinearFit {
  double a = 0, b = 0;
};
// HKS05 eq. 2 calibration for one muscle group: the line tau = a E + b through the exercise's samples of
// produced torque tau (N m, >= 0, against HAL's reference torque) and RMS envelope E (V). The torque
// is known exactly and the envelope carries the estimation noise, so E is regressed on tau
// (E = c tau + d) and the line inverted (a = 1/c, b = -d/c): an ordinary least squares of tau on the
// noisy E is biased low by var(noise) / var(E) (errors in variables; 10 % in the twin's exercise at
// 2-12 % MVC, where a 100 ms envelope of the relaxed-level noise is as large as the signal). Same
// length >= 2; throws std::invalid_argument if tau is constant or E does not grow with tau.
LinearFit FitEmgToTorque(const std::vector<double>& E, const std::vector<double>& tau);

struct HalEmgCoefficients {
  LinearFit extensor, flexor;  // a in N m/V, b in N m
  // Relaxed RMS envelope of each channel (V), measured at rest during the calibration; 0 = the
  // paper's HKS05 eq. 2 on the raw envelope. See NoiseCorrectedEnvelope.
  double baseline_e = 0, baseline_f = 0;
};
// Noise-corrected envelope sqrt(max(E^2 - E0^2, 0)) (V) of an RMS envelope E (V, HKS05 eq. 1) with relaxed
// level E0 (V). Our addition (Hayashi is silent): the relaxed noise (0.1 V / 0.04 V, Hayashi sec. IV)
// is independent of the muscle signal, so their powers add, E^2 = (A e)^2 + E0^2, and E itself is
// a hyperbola in the activation e, flat near rest. The seated swing lives at 0-5 % MVC, where A e is
// comparable with E0, so a straight line (HKS05 eq. 2) in E cannot fit the calibration and the swing at
// once (seed 1: slope 1.25x too steep at swing level, under-estimate near rest). Subtracting the
// noise power (noise-corrected RMS, as Clancy & Hogan's EMG amplitude estimators) makes the envelope
// proportional to e, i.e. to the contraction torque, which is what HKS05 eq. 2 assumes.
double NoiseCorrectedEnvelope(double E, double E0);
// HKS05 eq. 2: mu^ = (a_e E_e' + b_e) - (a_f E_f' + b_f), N m (positive = extension), with E' the
// noise-corrected envelopes (E' = E when the baselines are 0, the paper's form).
double EstimateMuscleTorque(const HalEmgCoefficients& c, double E_e, double E_f);

// Passive one-link parameters of HKS05 eq. 14/15: I thdd + B thd + Mgl sin th = tau.
struct OneLinkPassive {
  double I = 0;    // kg m^2
  double B = 0;    // N m s/rad (D + R for HKS05 eq. 14, R for HKS05 eq. 15)
  double mgl = 0;  // N m
};
// Least squares of HKS05 eq. 14/15 from a relaxed record: th (rad) and tau (N m) every dt (s);
// th smoothed by a zero-phase 2nd-order low-pass at fc (Hz) and differentiated centrally.
// Precondition: same length >= 16; th excites inertia, damping and gravity (a swing).
OneLinkPassive IdentifyOneLinkPassive(const std::vector<double>& th, const std::vector<double>& tau,
                                      double dt, double fc = 20.0);

// On-line estimation of the operator's viscosity D and stiffness K, HKS05 eq. 8-13.
struct ViscoelasticRlsConfig {
  double dt = 1e-3;     // sample period T_d, s
  double rho = 0.999;   // forgetting factor (0 << rho < 1), memory ~ dt/(1 - rho) = 1 s
  double p0 = 1e6;      // P(0) = p0 I (beta of HKS05 eq. 13)
  // Anti-windup (our addition): with rho < 1, P grows as rho^-k in unexcited directions (operator at
  // rest) until it overflows; trace(P) is capped at p_max by uniform scaling.
  double p_max = 1e9;
  // E(delta) = delta^2 + e1 delta + e2, the state-variable filter of HKS05 eq. 11. The paper gives no
  // values; we use a double pole at -pf: e1 = 2 pf, e2 = pf^2, pf = 20 rad/s (above the 0.5 Hz
  // swing and the leg's natural frequency, below the noise).
  double pf = 20.0;
  // Known passive parameters (HKS05 eq. 14-15) used to split D' = D + R and K' = K + G(th) (HKS05 eq. 8), and
  // the initial estimate.
  double R = 0.0;       // actuator viscosity, N m s/rad
  double mgl = 0.0;     // M g l of leg + exoskeleton, N m
  double I0 = 0.3, D0 = 1.0, K0 = 5.0;  // initial I (kg m^2), D, K (operator)
  // false: the paper's HKS05 eq. 8, K' = K + G(th) estimated as one slowly varying parameter (G varies
  // with th along the swing, so K^ carries a ripple of the order of mgl (1 - sin th / th)).
  // true (our extension): the known gravity moment is moved into the input, u - mgl sin th, so the
  // RLS estimates K' = K directly.
  bool gravity_in_input = false;
  // false: the paper's HKS05 eq. 11-13, all four X estimated, I^ = 1/X4.
  // true (our extension): I is the identified I0 of HKS05 eq. 14 (an invariant parameter like M g l and
  // R), X3 = T/(2 I0) and X4 = 1/I0 are held, and the RLS estimates X1, X2 only. In a near-sinusoidal
  // swing th'' ~ -w^2 th, so K' and I w^2 are nearly collinear and the four-parameter RLS trades
  // them: K' = (e2 - X2) I^ inherits I^'s error (at 10 % co-contraction, K^ 57-81 % high with I^
  // 2-100x the truth at the end of a 12 s run; scenarios/hal3_rls_tracking.yaml).
  bool known_inertia = false;
};

class ViscoelasticRls {
 public:
  explicit ViscoelasticRls(const ViscoelasticRlsConfig& cfg);
  // One sample: measured angle th(k) (rad) and input u(k) = tau + mu + sigma (N m), HKS05 eq. 9.
  // Updates X^ (HKS05 eq. 13) with the regressor phi(k) built from data up to k-1, then the filters.
  void Step(double th, double u);
  double I() const;        // kg m^2, from X4 = 1/I
  double Dprime() const;   // D' = D + R, N m s/rad
  double Kprime() const;   // K' = K + G(th), N m/rad
  double D() const { return Dprime() - cfg_.R; }
  double K() const;        // K' - G(th_last), HKS05 eq. 8
  const Eigen::Vector4d& X() const { return X_; }
  double last_error() const { return err_; }  // e(k) of HKS05 eq. 12, rad

 private:
  ViscoelasticRlsConfig cfg_;
  double e1_, e2_;
  Eigen::Vector4d X_;
  Eigen::Matrix4d P_;
  double s1t_ = 0, s2t_ = 0, s1u_ = 0, s2u_ = 0;  // filter states of th and u
  double th_last_ = 0, err_ = 0;
};

// G(th) of HKS05 eq. 8: Mgl sin(th)/th, Mgl at th = 0.
double GravityStiffness(double mgl, double th);

// State observer of HKS05 eq. 16 with the adaptive gains of HKS05 eq. 17. Poles of the error dynamics
// fixed at -lambda1, -lambda2 (1/s, positive) whatever the current I, D', K'. HKS05 eq. 17 as printed
// (g1 = l1 - l2 - D'/I, g2 = l1 l2 - g1 D'/I) is garbled; pole placement for A = [0 1; -K'/I -D'/I],
// C = [1 0] gives g1 = l1 + l2 - D'/I, g2 = l1 l2 - K'/I - g1 D'/I, which we use.
class AdaptiveObserver {
 public:
  // dt: s; lambda1, lambda2 > 0 (default time constants ~ 17 / 13 ms, below a 40 ms EMD).
  explicit AdaptiveObserver(double dt = 1e-3, double lambda1 = 60.0, double lambda2 = 80.0);
  // One step with measured th (rad), input u (N m) and the current model I, D', K'.
  void Step(double th, double u, double I, double Dp, double Kp);
  double theta() const { return x1_; }
  double velocity() const { return x2_; }
  void Reset(double th, double thd = 0) { x1_ = th, x2_ = thd; }

 private:
  double dt_, l1_, l2_;
  double x1_ = 0, x2_ = 0;
};

// Configuration of the whole assist law.
struct HalAssistConfig {
  double dt = 1e-3;
  double alpha_mu = 1.0;    // HKS05 eq. 3; Hayashi's experiment 2: 1.0
  double alpha_zeta = 0.5;  // HKS05 eq. 5; experiment 2: 0.5
  HalEmgCoefficients emg;
  ViscoelasticRlsConfig rls;
  double lambda1 = 60.0, lambda2 = 80.0;
  double tau_max = 60.0;  // actuator limit, N m (models/hal3_knee.xml ctrlrange)
  // Known Coulomb friction of HAL's actuator (N m; identified with HKS05 eq. 15, used by tau_c), moved out
  // of the RLS input: u = tau + mu^ - C tanh(thd^ / eps), thd^ the observer's previous velocity.
  // HKS05 eq. 4 has no Coulomb term, so the part of tau that only overcomes it would otherwise be read
  // as operator viscosity: C E|thd| / E[thd^2] (~0.25 N m s/rad, 7 % of D at 10 % co-contraction,
  // C = 0.4 N m). 0 = the paper's input (HKS05 eq. 9). Our extension.
  double friction_C = 0.0;
  double friction_eps = 0.05;  // rad/s, sgn(thd) ~ tanh(thd / eps); the runner passes tau_c's own
};

// Torques of one control step, N m.
struct HalAssistOutput {
  double tau = 0, tau_mu = 0, tau_zeta = 0, tau_c = 0, mu_hat = 0;
  double D = 0, K = 0, thd_hat = 0;
};

// The controller of HKS05 eq. 6. Each Step: mu^ from the envelopes (HKS05 eq. 2), tau_mu (HKS05 eq. 3); the RLS is
// fed the previous step's applied torque plus mu^ (HKS05 eq. 9: u = tau + mu, sigma = 0 seated); the
// observer gives thd^; tau_zeta from the current D^, K^ (HKS05 eq. 5, D^, K^ clamped >= 0); tau_c is the
// caller's compensation of HAL's own impedance (controller/virtual_impedance.h), or 0 (Exp. 1 uses
// tau_c alone: set alpha_mu = alpha_zeta = 0).
class HalAssistController {
 public:
  explicit HalAssistController(const HalAssistConfig& cfg);
  HalAssistOutput Step(double th, double E_e, double E_f, double tau_c = 0.0);
  const ViscoelasticRls& rls() const { return rls_; }
  const AdaptiveObserver& observer() const { return obs_; }

 private:
  HalAssistConfig cfg_;
  ViscoelasticRls rls_;
  AdaptiveObserver obs_;
  double tau_prev_ = 0, thd_prev_ = 0;
  bool started_ = false;
};

}  // namespace exotwin::controller
