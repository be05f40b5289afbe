// Simulated leg muscles of the twin's human (issue 6): GMAX, VM, RF, ST, GAS with the joint actions of
// HJ15 eq. 23-24, first-order activation dynamics, an electromechanical delay, the
// angle/velocity dependence of HJ15 eq. 26-27 with subject-specific ground truth alpha, beta, gamma,
// and co-contraction raising the joint viscosity D and stiffness K (HKS05 eq. 4).
//
// Convention (DESIGN.md): q = (th1 hip, th2 knee); hip flexion positive, knee flexion NEGATIVE.
// A knee extensor pulls th2 from negative (flexed) towards 0, i.e. in the POSITIVE direction of th2;
// a knee flexor acts along -th2. Hence the signs of HJ15 eq. 23-24:
//   hip:  +RF - GMAX - ST          knee: +VM + RF - ST - GAS
// HAL (Hayashi, Lee & Sankai) measures its knee angle from the hanging lower leg, extension positive:
// th_HAL = th2 + pi/2 with the hip at 90 deg; torques have the same sign in both conventions.
//
// Units: torques N m, angles rad, velocities rad/s. The paper gives beta in 1/deg and gamma in
// 1/(deg/s); this API stores SI (1/rad, s/rad); see BetaFromPerDeg / GammaFromPerDegPerS.
// alpha: the paper's LE is "normalized to MVC" with alpha of order 1-3; we read its LE as percent of
// MVC (alpha in N m per % MVC, so 1.88 -> 188 N m at MVC, a plausible hip-flexor MVC). Here the
// normalized envelope and the activation are fractions of MVC (0..1) and alpha is the torque at MVC
// (N m) = 100 x the paper's value. That reading is ours; the paper does not state the unit.
#pragma once
#include <array>
#include <cstdint>
#include <vector>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "core/ring_queue.h"
#include "core/rng.h"
#include "core/units.h"

namespace exotwin {

enum class Muscle { kGMAX = 0, kVM = 1, kRF = 2, kST = 3, kGAS = 4 };
constexpr int kNumMuscles = 5;
using MuscleVec = Eigen::Matrix<double, kNumMuscles, 1>;  // one value per muscle, Muscle order

// "GMAX", "VM", "RF", "ST", "GAS".
const char* MuscleName(Muscle m);
// Index -> Muscle (0..4). Precondition: 0 <= i < kNumMuscles.
inline Muscle MuscleAt(int i) { return static_cast<Muscle>(i); }
// The muscle named `name` (MuscleName's spelling) into *m; false when no muscle has that name.
bool MuscleByName(const std::string& name, Muscle* m);

// The EMG amplifier's channel names, channel c recording muscle MuscleAt(c) ("GMAX", "VM", ...).
std::vector<std::string> EmgChannelNames();

// Action sign of muscle m at joint j (0 hip, 1 knee) in the EXOwheel convention: +1 acts along +q_j,
// -1 along -q_j, 0 does not span the joint (HJ15 eq. 23-24).
int ActionSign(Muscle m, int joint);

// The random stream of the muscle and EMG models: Marsaglia's polar method (core/rng.h). Seed it with
// MixSeed(seed ^ stream id).
using MuscleRng = NormalRng<NormalPolar>;

// Conversions from the paper's units (Table 7 gives 10^-3 of these).
inline double BetaFromPerDeg(double beta_per_deg) { return beta_per_deg * kDegPerRad; }       // 1/rad
inline double GammaFromPerDegPerS(double g_per_deg_s) { return g_per_deg_s * kDegPerRad; }  // s/rad

// Ground-truth muscle parameters of one subject.
struct MuscleParams {
  // alpha(m, j): torque (N m) muscle m produces at joint j at full activation, q = q_c, qd = 0;
  // >= 0; zero where the muscle does not span the joint.
  Eigen::Matrix<double, kNumMuscles, 2> alpha = Eigen::Matrix<double, kNumMuscles, 2>::Zero();
  Eigen::Vector2d beta{0, 0};     // 1/rad, HJ15 eq. 26-27 (per joint)
  Eigen::Vector2d gamma{0, 0};    // s/rad, HJ15 eq. 26-27
  Eigen::Vector2d theta_c{0.0, -1.5707963267948966};  // calibration angles (HJ15 eq. 27: 0, -90 deg)
  double tau_act = 0.015;    // activation time constant, s (Zajac 1989: 10-20 ms)
  double tau_deact = 0.050;  // deactivation time constant, s (Zajac 1989: 40-60 ms)
  double emd = 0.040;        // electromechanical delay EMG -> force, s (Cavanagh & Komi 1979: 30-50 ms)
  // Co-contraction viscoelasticity (HKS05 eq. 4): per joint j
  //   K_j = K0_j + cK_j * S_j,  D_j = D0_j + cD_j * S_j,  S_j = 2 min(E_j, F_j)  (N m)
  // with E_j, F_j the summed alpha * a of the muscles acting along +q_j and -q_j: the co-contracted
  // (balanced) part of flexor + extensor activity. Our choice: a plain flexor + extensor sum makes
  // agonist activity stiffen the joint towards q_rest and fight the motion it drives (unstable
  // with a saturated biarticular RF). The viscoelastic torque is -D_j qd_j - K_j (q_j - q_rest_j),
  // Hayashi's K theta about the hanging leg for the knee. K0, D0 default to 0 because the plant
  // already carries the relaxed passive moment (Riener) and the exoskeleton friction.
  Eigen::Vector2d K0{0, 0}, D0{0, 0};     // N m/rad, N m s/rad
  // cK, cD: our choice, sized so that 10 % co-contraction of all knee muscles (S ~ 70 N m) gives
  // K ~ 20 N m/rad and D ~ 2 N m s/rad, comparable with the seated leg's gravity stiffness
  // (mgl ~ 10 N m/rad); the papers give no values.
  Eigen::Vector2d cK{0.3, 0.3};          // 1/rad
  Eigen::Vector2d cD{0.03, 0.03};        // s/rad
  Eigen::Vector2d q_rest{0.0, -1.5707963267948966};  // rad; knee: hanging when seated (HAL th = 0)
};

// Means of Hwang & Jeon 2015 (HJ15 eq. 25 text and Table 7, "identified" rows), in this API's units.
MuscleParams PaperMeanMuscleParams();

// Subject-specific ground truth drawn from the paper's means and SDs (alpha: HJ15 eq. 25 text; beta,
// gamma: Table 7 identified rows), normal, redrawn while below 20 % of the mean (no sign flips).
// The same seed gives the same bits. Activation time constants and EMD are drawn +-20 % uniform.
MuscleParams DrawMuscleParams(uint64_t seed);

// Torques of the muscles at one instant (N m, EXOwheel convention).
struct MuscleTorques {
  Eigen::Vector2d contraction{0, 0};    // HJ15 eq. 26-27 structure
  Eigen::Vector2d viscoelastic{0, 0};   // -D qd - K (q - q_rest), co-contraction dependent
  Eigen::Vector2d total() const { return contraction + viscoelastic; }
  Eigen::Vector2d K{0, 0}, D{0, 0};     // current stiffness (N m/rad) and viscosity (N m s/rad)
};

// HJ15 eq. 26-27 factor for a muscle of action sign s at one joint:
//   s = +1: 1 + beta (q - q_c) - gamma qd;   s = -1: 1 - beta (q - q_c) + gamma qd;  clamped >= 0
// (a muscle cannot push; the paper's linear model has no clamp).
double ForceFactor(int s, double beta, double gamma, double q, double q_c, double qd);

// Contraction torque at joint j of activations a (0..1), HJ15 eq. 26-27 with alpha, beta, gamma.
Eigen::Vector2d ContractionTorque(const MuscleParams& p, const MuscleVec& a, const Eigen::Vector2d& q,
                                  const Eigen::Vector2d& qd);

// The muscles of one subject: excitation u (neural drive, 0..1) -> electrical activation e (first
// order, tau_act rising / tau_deact falling; what the EMG shows) -> mechanical activation
// a(t) = e(t - emd) -> torques. Real-time safe after construction (fixed-size delay line).
class MuscleModel {
 public:
  // dt: step of Step(), s (> 0). Starts relaxed (all zero).
  MuscleModel(const MuscleParams& params, double dt);
  // Advances one step dt with excitation u (clipped to [0, 1]).
  void Step(const MuscleVec& u);
  // Torques at state (q, qd) from the current mechanical activation.
  MuscleTorques Torques(const Eigen::Vector2d& q, const Eigen::Vector2d& qd) const;
  const MuscleVec& electrical_activation() const { return e_; }  // drives the EMG (leads force)
  const MuscleVec& mechanical_activation() const { return a_; }  // drives the force
  const MuscleParams& params() const { return p_; }
  double dt() const { return dt_; }
  void Reset();

 private:
  MuscleParams p_;
  double dt_;
  MuscleVec e_ = MuscleVec::Zero(), a_ = MuscleVec::Zero();
  std::vector<MuscleVec> delay_;  // ring buffer of e, length round(emd/dt)
  size_t head_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Behaviours: generators of the excitation u(t, q, qd) in [0, 1] per muscle.
class Behaviour {
 public:
  virtual ~Behaviour() = default;
  // Excitation at time t (s) given the measured state (rad, rad/s).
  virtual MuscleVec Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) = 0;
};

// Relaxed: zero drive.
class RelaxedBehaviour : public Behaviour {
 public:
  MuscleVec Excitation(double, const Eigen::Vector2d&, const Eigen::Vector2d&) override {
    return MuscleVec::Zero();
  }
};

// One block of a piecewise-linear excitation programme (isometric or MVC trials).
struct ContractionBlock {
  double t_start = 0;       // s
  double ramp = 1.0;        // s up and s down
  double hold = 2.0;        // s at the peak
  MuscleVec peak = MuscleVec::Zero();  // excitation at the plateau per muscle (0..1)
};

// Plays contraction blocks (trapezoids, summed where they overlap, clipped to [0, 1]).
class ContractionProgramme : public Behaviour {
 public:
  explicit ContractionProgramme(std::vector<ContractionBlock> blocks) : blocks_(std::move(blocks)) {}
  MuscleVec Excitation(double t, const Eigen::Vector2d&, const Eigen::Vector2d&) override;
  double duration() const;  // end of the last block, s
  const std::vector<ContractionBlock>& blocks() const { return blocks_; }

 private:
  std::vector<ContractionBlock> blocks_;
};

// Isometric calibration programme for joint (0 hip, 1 knee) as in Hwang & Jeon section 4.3: n
// contractions alternating flexion / extension, each at a random level in [lo, hi] of MVC; the
// agonists of the direction get the level (split evenly), every other muscle spanning the joint
// gets `cocontraction` x level. Starts after `t0` s of rest; `rest` s between contractions.
ContractionProgramme IsometricProgramme(int joint, int n, double lo, double hi, double cocontraction,
                                        uint64_t seed, double t0 = 1.0, double rest = 1.5);

// MVC trials of one muscle: `trials` blocks at full drive (ramp 0.5 s, hold 3 s), `rest` s apart
// (the paper rests 2 min; the twin has no fatigue, so a short rest changes nothing).
ContractionProgramme MvcProgramme(Muscle m, int trials = 3, double t0 = 1.0, double rest = 2.0);

// Intended motion of a voluntary behaviour: fills q, qd, qdd (rad, rad/s, rad/s^2) at time t.
using IntendedMotion = std::function<void(double t, Eigen::Vector2d& q, Eigen::Vector2d& qd,
                                          Eigen::Vector2d& qdd)>;

// Gains and shape of the voluntary feedback law.
struct TrackingGains {
  // Defaults sized for the human limb alone (M11 ~ 2.7, M22 ~ 0.4 kg m^2) with the ~55 ms of
  // activation + electromechanical delay in the loop.
  Eigen::Vector2d kp{100.0, 40.0};   // N m/rad
  Eigen::Vector2d kd{15.0, 4.0};     // N m s/rad
  Eigen::Vector2d inertia{0.0, 0.0}; // kg m^2 feed-forward inertia (0: none)
  Eigen::Vector2d active{1.0, 1.0};  // 1 = joint driven voluntarily, 0 = left relaxed
  // Neural transmission delay of the feedback (s): the law sees q, qd as they were feedback_delay
  // ago (proprioceptive long-latency / voluntary corrections: 50-150 ms, e.g. Kandel ch. 35;
  // 0 = none, the default of the EXOwheel behaviours). The feed-forward (intended motion) is not
  // delayed. The muscles' own co-contraction viscoelasticity acts without this delay.
  double feedback_delay = 0.0;
  // Mix of the co-contraction drive c among the muscles of a group (same action at an active joint):
  // false: every muscle at c; true: muscle m at c alpha(m, j) / max alpha of its group at j (the
  // group's synergy, the mix of a voluntary contraction: min-norm allocation is alpha-proportional).
  bool cocontraction_synergy = false;
};

// Solves min_u 1/2 u'Hu - f'u over 0 <= u_m <= 1 for the muscles with used[m] (the others stay 0),
// H symmetric positive definite on the used block. Exact (primal active set, Nocedal & Wright
// alg. 16.3, finite for a strictly convex QP); starts from clip(start). Returns the minimiser;
// `iterations` (optional) receives the iterations used (capped at 4 kNumMuscles^2).
MuscleVec SolveUnitBoxQp(const Eigen::Matrix<double, kNumMuscles, kNumMuscles>& H, const MuscleVec& f,
                         const std::array<bool, kNumMuscles>& used, const MuscleVec& start,
                         int* iterations = nullptr);

// Voluntary tracking: desired torque tau_d = I_ff qdd* + kp (q* - q) + kd (qd* - qd) + ff(t, q, qd)
// per active joint, allocated to the muscles spanning the active joints by the box-constrained least
// squares min |A u - tau_d|^2 + lambda |u - c|^2, 0 <= u <= 1 (A: signed alpha of HJ15 eq. 23-24; c the
// co-contraction drive c(t, q, qd)), so biarticular RF/ST are balanced by the monoarticular muscles
// and the antagonists stay near c. The subject does not know its own beta/gamma nor the
// electromechanical delay; the feedback corrects them.
class VoluntaryTracking : public Behaviour {
 public:
  using CoContraction = std::function<double(double t, const Eigen::Vector2d& q,
                                             const Eigen::Vector2d& qd)>;
  using FeedForward = std::function<Eigen::Vector2d(double t, const Eigen::Vector2d& q,
                                                    const Eigen::Vector2d& qd)>;
  VoluntaryTracking(const MuscleParams& p, IntendedMotion motion, TrackingGains gains,
                    CoContraction cocontraction = nullptr, FeedForward ff = nullptr);
  MuscleVec Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) override;
  Eigen::Vector2d last_desired_torque() const { return tau_d_; }

 private:
  MuscleParams p_;
  IntendedMotion motion_;
  TrackingGains g_;
  CoContraction cc_;
  FeedForward ff_;
  Eigen::Vector2d tau_d_{0, 0};
  // Co-contraction share of muscle m at joint j (1, or alpha(m, j) / its group's largest with
  // cocontraction_synergy): constant for the subject, computed once.
  Eigen::Matrix<double, kNumMuscles, 2> cc_share_ = Eigen::Matrix<double, kNumMuscles, 2>::Ones();
  struct Sensed {
    double t;
    Eigen::Vector2d q, qd;
  };
  RingQueue<Sensed> sensed_;  // history over the last feedback_delay s (delayed feedback)
};

// The exaggerated gait's intended motion from the pattern's (q, qd, qdd) = (q_b, qd_b, qdd_b),
// replaced in place (rad, rad/s, rad/s^2). outward_gate <= 0: q* = mean + gain (q_b - mean) (the
// amplitude intent). outward_gate = s0 > 0 (rad^2/s): the exaggeration (gain - 1)(q_b - mean) is
// weighted per joint by w = (1 + tanh((q_b - mean) qd_b / s0)) / 2: pushed while the pattern moves
// away from the mean, faded while it comes back; qd* is the exact derivative of q*.
void ExaggeratedTarget(const Eigen::Vector2d& mean, double gain, double outward_gate, Eigen::Vector2d& q,
                       Eigen::Vector2d& qd, Eigen::Vector2d& qdd);

// Exaggerated gait (Hwang & Jeon section 4.3): relaxed until t_active, then the subject tracks the
// exoskeleton's gait pattern `base` amplified about `mean` by `gain` (> 1: more flexion/extension
// than the pattern), with co-contraction `cocontraction` (fraction of MVC).
class ExaggeratedGait : public Behaviour {
 public:
  // outward_gate: see ExaggeratedTarget (0 = the amplitude intent).
  ExaggeratedGait(const MuscleParams& p, IntendedMotion base, Eigen::Vector2d mean, double gain,
                  double t_active, double cocontraction = 0.02, TrackingGains gains = {},
                  double outward_gate = 0.0);
  MuscleVec Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) override;

 private:
  double t_active_;
  VoluntaryTracking tracking_;
};

// Seated knee swing of Hayashi et al. section III: hip at 90 deg, the knee swings at `freq` Hz
// between HAL angles +1.0 (extension) and -0.3 rad, i.e. th2 = -pi/2 + 0.35 + 0.65 sin(2 pi f t);
// co-contraction `cc_down` during swing-down (HAL angle > 0 and velocity < 0), `cc_up` otherwise.
// The hip is not driven (active = {0, 1}).
class KneeSwingBehaviour : public Behaviour {
 public:
  // mgl_internal: the subject's internal model of the lower leg's gravity moment amplitude (N m),
  // used as feed-forward mgl sin(th_HAL); 0 = pure feedback.
  KneeSwingBehaviour(const MuscleParams& p, double freq = 0.5, double cc_up = 0.0,
                     double cc_down = 0.05, double mgl_internal = 0.0,
                     TrackingGains gains = KneeSwingGains());
  MuscleVec Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) override;
  // The intended knee angle th2 (EXOwheel convention, rad) at t.
  static void Intended(double t, double freq, Eigen::Vector2d& q, Eigen::Vector2d& qd,
                       Eigen::Vector2d& qdd);
  static TrackingGains KneeSwingGains();
  Eigen::Vector2d last_desired_torque() const { return tracking_.last_desired_torque(); }

 private:
  VoluntaryTracking tracking_;
};

}  // namespace exotwin
