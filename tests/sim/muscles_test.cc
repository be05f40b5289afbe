// Tests of sim/muscles.h: joint actions (HJ15 eq. 23-24) checked against the closed-form leg dynamics,
// activation dynamics and delay, the HJ15 eq. 26-27 structure, co-contraction stiffness, seeded
// ground-truth draws against the paper's means/SDs, and the behaviours in closed loop.
#include "sim/muscles.h"

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "model/leg_dynamics.h"

namespace exotwin {
namespace {

constexpr double kPi = 3.14159265358979323846;
int I(Muscle m) { return static_cast<int>(m); }

MuscleVec Only(Muscle m, double a) {
  MuscleVec v = MuscleVec::Zero();
  v[I(m)] = a;
  return v;
}

LumpedParams Human() {  // DESIGN.md example human block
  LumpedParams h;
  h.J1 = 1.69; h.J2 = 0.37; h.X1 = 4.54; h.X2 = 1.20; h.Y1 = -0.16; h.Y2 = 0.42;
  return h;
}

// Forward dynamics of the closed-form leg (HJ15 eq. 3 with tau_R = 0): M qdd = tau - V - G.
Eigen::Vector2d Accel(const LumpedParams& p, const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                      const Eigen::Vector2d& tau) {
  const double L1 = 0.41, g = 9.81;
  return MassMatrix(p, L1, q[1]).ldlt().solve(tau - CoriolisCentrifugal(p, L1, q, qd) -
                                             GravityTorque(p, g, q));
}

TEST(Muscles, ActionSignsFollowEq23And24) {
  // hip: +RF - GMAX - ST; knee: +VM + RF - ST - GAS.
  EXPECT_EQ(ActionSign(Muscle::kRF, 0), +1);
  EXPECT_EQ(ActionSign(Muscle::kGMAX, 0), -1);
  EXPECT_EQ(ActionSign(Muscle::kST, 0), -1);
  EXPECT_EQ(ActionSign(Muscle::kVM, 0), 0);
  EXPECT_EQ(ActionSign(Muscle::kGAS, 0), 0);
  EXPECT_EQ(ActionSign(Muscle::kVM, 1), +1);
  EXPECT_EQ(ActionSign(Muscle::kRF, 1), +1);
  EXPECT_EQ(ActionSign(Muscle::kST, 1), -1);
  EXPECT_EQ(ActionSign(Muscle::kGAS, 1), -1);
  EXPECT_EQ(ActionSign(Muscle::kGMAX, 1), 0);
  EXPECT_STREQ(MuscleName(Muscle::kGAS), "GAS");
}

// The amplifier's channels as the video's EMG panel and the logs label them: HJ15's five muscles
// (gluteus maximus, vastus medialis, rectus femoris, semitendinosus, gastrocnemius) in channel order.
TEST(Muscles, EmgChannelNamesAreTheMusclesInChannelOrder) {
  const std::vector<std::string> expected = {"GMAX", "VM", "RF", "ST", "GAS"};
  EXPECT_EQ(EmgChannelNames(), expected);
}

// Independent check of the convention with the physics: seated (hip 90 deg, knee -90 deg, at rest),
// a knee extensor (VM) must extend the knee (th2 towards 0: increase), a knee flexor (GAS) flex it,
// RF must flex the hip (th1 increase), GMAX extend it, with gravity cancelled at the start.
TEST(Muscles, ExtensorsExtendAndFlexorsFlexInTheClosedFormLeg) {
  const MuscleParams p = PaperMeanMuscleParams();
  const LumpedParams h = Human();
  const Eigen::Vector2d q0(kPi / 2, -kPi / 2), qd0(0, 0);
  const Eigen::Vector2d g0 = GravityTorque(h, 9.81, q0);
  auto response = [&](Muscle m) {
    const Eigen::Vector2d tau = ContractionTorque(p, Only(m, 0.05), q0, qd0) + g0;
    return Accel(h, q0, qd0, tau);
  };
  EXPECT_GT(response(Muscle::kVM)[1], 0.0);    // knee extends: th2 increases towards 0
  EXPECT_LT(response(Muscle::kGAS)[1], 0.0);   // knee flexes: th2 more negative
  EXPECT_GT(response(Muscle::kRF)[0], 0.0);    // hip flexes
  EXPECT_LT(response(Muscle::kGMAX)[0], 0.0);  // hip extends
}

TEST(Muscles, ContractionTorqueHasTheStructureOfEq26And27) {
  const MuscleParams p = DrawMuscleParams(7);
  MuscleVec a;
  a << 0.3, 0.2, 0.4, 0.1, 0.25;
  const Eigen::Vector2d q(0.4, -1.1), qd(1.2, -2.0);
  const Eigen::Vector2d tau = ContractionTorque(p, a, q, qd);
  // HJ15 eq. 26: hip = alpha_RF LE_RF {1 + b(q - qc) - g qd} - (alpha_GMAX LE_GMAX + alpha_ST LE_ST) {1 - ...}.
  const double dq1 = q[0] - p.theta_c[0], dq2 = q[1] - p.theta_c[1];
  const double hip = p.alpha(I(Muscle::kRF), 0) * a[I(Muscle::kRF)] *
                         (1 + p.beta[0] * dq1 - p.gamma[0] * qd[0]) -
                     (p.alpha(I(Muscle::kGMAX), 0) * a[I(Muscle::kGMAX)] +
                      p.alpha(I(Muscle::kST), 0) * a[I(Muscle::kST)]) *
                         (1 - p.beta[0] * dq1 + p.gamma[0] * qd[0]);
  const double knee = (p.alpha(I(Muscle::kVM), 1) * a[I(Muscle::kVM)] +
                       p.alpha(I(Muscle::kRF), 1) * a[I(Muscle::kRF)]) *
                          (1 + p.beta[1] * dq2 - p.gamma[1] * qd[1]) -
                      (p.alpha(I(Muscle::kST), 1) * a[I(Muscle::kST)] +
                       p.alpha(I(Muscle::kGAS), 1) * a[I(Muscle::kGAS)]) *
                          (1 - p.beta[1] * dq2 + p.gamma[1] * qd[1]);
  EXPECT_NEAR(tau[0], hip, 1e-9);
  EXPECT_NEAR(tau[1], knee, 1e-9);
  // Concentric (shortening) lowers the force, eccentric raises it.
  EXPECT_LT(ForceFactor(+1, 0.1, 0.1, 0, 0, 2.0), 1.0);
  EXPECT_GT(ForceFactor(-1, 0.1, 0.1, 0, 0, 2.0), 1.0);
  EXPECT_EQ(ForceFactor(+1, 0.1, 0.1, 0, 0, 100.0), 0.0);  // a muscle cannot push
}

TEST(Muscles, ActivationTimeConstantsAndElectromechanicalDelay) {
  MuscleParams p = PaperMeanMuscleParams();
  const double dt = 1e-3;
  MuscleModel m(p, dt);
  const int n_act = static_cast<int>(std::lround(p.tau_act / dt));
  for (int k = 0; k < n_act; ++k) m.Step(MuscleVec::Constant(1.0));
  EXPECT_NEAR(m.electrical_activation()[0], 1 - std::exp(-1.0), 1e-3);
  // Mechanical activation is e delayed by emd: still zero before emd has elapsed.
  EXPECT_EQ(m.mechanical_activation()[0], 0.0);
  for (int k = n_act; k < 2000; ++k) m.Step(MuscleVec::Constant(1.0));
  EXPECT_NEAR(m.mechanical_activation()[0], 1.0, 1e-6);
  const int n_deact = static_cast<int>(std::lround(p.tau_deact / dt));
  for (int k = 0; k < n_deact; ++k) m.Step(MuscleVec::Zero());
  EXPECT_NEAR(m.electrical_activation()[0], std::exp(-1.0), 1e-3);
  // Delay: the mechanical activation now equals e from emd ago (still ~1 if emd < tau_deact ...).
  MuscleModel d(p, dt);
  std::vector<double> e;
  for (int k = 0; k < 300; ++k) {
    d.Step(MuscleVec::Constant(k >= 50 ? 1.0 : 0.0));
    e.push_back(d.electrical_activation()[1]);
    const int lag = static_cast<int>(std::lround(p.emd / dt));
    if (k >= lag) {
      EXPECT_DOUBLE_EQ(d.mechanical_activation()[1], e[k - lag]);
    }
  }
}

TEST(Muscles, CoContractionRaisesStiffnessAndViscosity) {
  MuscleParams p = PaperMeanMuscleParams();
  MuscleModel m(p, 1e-3);
  const Eigen::Vector2d q(0, -kPi / 2 + 0.2), qd(0, 0.5);
  const MuscleTorques relaxed = m.Torques(q, qd);
  EXPECT_EQ(relaxed.K[1], 0.0);
  MuscleVec cc = MuscleVec::Constant(0.1);
  for (int k = 0; k < 1000; ++k) m.Step(cc);
  const MuscleTorques t = m.Torques(q, qd);
  const double S = 2 * 0.1 * std::min(p.alpha(I(Muscle::kVM), 1) + p.alpha(I(Muscle::kRF), 1),
                                      p.alpha(I(Muscle::kST), 1) + p.alpha(I(Muscle::kGAS), 1));
  EXPECT_NEAR(t.K[1], p.cK[1] * S, 1e-6);
  EXPECT_NEAR(t.D[1], p.cD[1] * S, 1e-6);
  EXPECT_NEAR(t.viscoelastic[1], -t.D[1] * 0.5 - t.K[1] * 0.2, 1e-6);
  EXPECT_GT(t.K[1], 15.0);  // 10 % co-contraction: ~20 N m/rad with the default cK
  // Agonist activity alone does not stiffen the joint.
  MuscleModel ag(p, 1e-3);
  for (int k = 0; k < 1000; ++k) ag.Step(Only(Muscle::kVM, 0.3));
  EXPECT_EQ(ag.Torques(q, qd).K[1], 0.0);
}

TEST(Muscles, DrawsAreSeededAndFollowThePaperStatistics) {
  const MuscleParams a = DrawMuscleParams(42), b = DrawMuscleParams(42), c = DrawMuscleParams(43);
  EXPECT_EQ(a.alpha, b.alpha);
  EXPECT_EQ(a.beta, b.beta);
  EXPECT_NE(a.alpha, c.alpha);
  // Population statistics over many subjects: means and SDs of HJ15 eq. 25 text and Table 7.
  const int n = 4000;
  double s = 0, s2 = 0, sb = 0, sg = 0;
  for (int i = 0; i < n; ++i) {
    const MuscleParams p = DrawMuscleParams(1000 + i);
    const double x = p.alpha(I(Muscle::kVM), 1) / 100;
    s += x;
    s2 += x * x;
    sb += p.beta[0] / BetaFromPerDeg(1e-3);
    sg += p.gamma[1] / GammaFromPerDegPerS(1e-3);
  }
  const double mean = s / n, sd = std::sqrt(s2 / n - mean * mean);
  EXPECT_NEAR(mean, 2.53, 0.05);   // alpha_VM,2 = 2.53 +- 0.77
  EXPECT_NEAR(sd, 0.77, 0.06);
  // beta_1 = 3.27e-3 +- 1.53e-3 /deg, redrawn below 20 % of the mean: truncated-normal mean
  // 3.27 + 1.53 phi(a) / (1 - Phi(a)), a = (0.654 - 3.27) / 1.53 = -1.71 -> 3.418.
  EXPECT_NEAR(sb / n, 3.418, 0.06);
  EXPECT_NEAR(sg / n, 0.92, 0.05);  // gamma_2 = 0.92e-3 /(deg/s)
}

TEST(Muscles, IsometricAndMvcProgrammes) {
  ContractionProgramme iso = IsometricProgramme(1, 6, 0.1, 0.4, 0.1, 3);
  ASSERT_EQ(iso.blocks().size(), 6u);
  // Knee: first contraction in +th2 (extension): VM and RF agonists, ST/GAS co-contract less.
  const auto& b0 = iso.blocks()[0];
  EXPECT_GE(b0.peak[I(Muscle::kVM)], 0.1);
  EXPECT_LT(b0.peak[I(Muscle::kST)], 0.1);
  EXPECT_EQ(b0.peak[I(Muscle::kGMAX)], 0.0);
  const double mid = b0.t_start + b0.ramp + 0.5 * b0.hold;
  EXPECT_NEAR(iso.Excitation(mid, {0, 0}, {0, 0})[I(Muscle::kVM)], b0.peak[I(Muscle::kVM)], 1e-12);
  EXPECT_EQ(iso.Excitation(0.5, {0, 0}, {0, 0}).sum(), 0.0);  // rest before t0
  ContractionProgramme mvc = MvcProgramme(Muscle::kST);
  EXPECT_EQ(mvc.Excitation(2.5, {0, 0}, {0, 0})[I(Muscle::kST)], 1.0);
  EXPECT_EQ(mvc.Excitation(2.5, {0, 0}, {0, 0})[I(Muscle::kVM)], 0.0);
  EXPECT_NEAR(mvc.duration(), 1.0 + 3 * 4.0 + 2 * 2.0, 1e-12);
}

// One-link seated knee in HAL's convention (HKS05 eq. 4 without D, K):
// I thdd + R thd + Mgl sin th = tau_muscle. th_HAL = th2 + pi/2.
struct OneLinkKnee {
  double I = 0.35, R = 0.3, mgl = 10.0;
};

TEST(Muscles, SeatedKneeSwingReachesHalTargets) {
  const MuscleParams p = DrawMuscleParams(11);
  MuscleModel muscles(p, 1e-3);
  const OneLinkKnee leg;
  KneeSwingBehaviour swing(p, 0.5, 0.0, 0.05, leg.mgl);
  double th = 0.0, thd = 0.0, th_max = -10, th_min = 10;
  double ext_up = 0, flex_up = 0, flex_down = 0;
  int n_up = 0, n_down = 0;
  for (int k = 0; k < 20000; ++k) {
    const double t = k * 1e-3;
    const Eigen::Vector2d q(kPi / 2, th - kPi / 2), qd(0, thd);
    muscles.Step(swing.Excitation(t, q, qd));
    const double tau = muscles.Torques(q, qd).total()[1];
    const double thdd = (tau - leg.R * thd - leg.mgl * std::sin(th)) / leg.I;
    thd += 1e-3 * thdd;
    th += 1e-3 * thd;
    if (t > 6) {
      th_max = std::max(th_max, th);
      th_min = std::min(th_min, th);
      const MuscleVec& e = muscles.electrical_activation();
      if (th > 0 && thd > 0) {
        ext_up += e[I(Muscle::kVM)];
        flex_up += e[I(Muscle::kGAS)];
        ++n_up;
      } else if (th > 0 && thd < 0) {
        flex_down += e[I(Muscle::kGAS)];
        ++n_down;
      }
    }
  }
  EXPECT_NEAR(th_max, 1.0, 0.15);
  EXPECT_NEAR(th_min, -0.3, 0.15);
  EXPECT_GT(ext_up / n_up, 3 * flex_up / n_up);  // extensor is the agonist in swing-up (Fig. 7)
  EXPECT_GT(flex_down / n_down, flex_up / n_up);  // co-contraction in swing-down
}

TEST(Muscles, ExaggeratedGaitAmplifiesThePatternAfterTheRelaxedPhase) {
  MuscleParams p = DrawMuscleParams(5);
  const Eigen::Vector2d mean(0.25, -0.6);
  p.q_rest = mean;  // co-contraction stiffness about the mean gait posture
  MuscleModel muscles(p, 1e-3);
  const LumpedParams h = Human();
  const auto base = [&](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
    const double w = 2 * kPi * 0.6;
    q = mean + Eigen::Vector2d(0.3 * std::sin(w * t), 0.4 * std::sin(w * t - 1.0));
    qd = Eigen::Vector2d(0.3 * w * std::cos(w * t), 0.4 * w * std::cos(w * t - 1.0));
    qdd = -w * w * (q - mean);
  };
  TrackingGains gains;
  gains.inertia = {2.5, 0.4};  // the subject's internal estimate of its limb inertia
  ExaggeratedGait gait(p, base, mean, 1.3, 2.0, 0.02, gains);
  Eigen::Vector2d q = mean, qd(0, 0);
  Eigen::Vector2d q_ref, qd_ref, qdd_ref;
  double err2 = 0, amp_hip = 0;
  int n = 0;
  for (int k = 0; k < 12000; ++k) {
    const double t = k * 1e-3;
    const MuscleVec u = gait.Excitation(t, q, qd);
    if (t < 2.0) {
      EXPECT_EQ(u.sum(), 0.0);
    }
    muscles.Step(u);
    // The exoskeleton is not in this loop: the subject drives the human limb, gravity compensated
    // by a support (the paper's body-weight support + exo): only the dynamics apart from G act.
    const Eigen::Vector2d tau = muscles.Torques(q, qd).total() + GravityTorque(h, 9.81, q);
    qd += 1e-3 * Accel(h, q, qd, tau);
    q += 1e-3 * qd;
    if (t > 6) {
      base(t, q_ref, qd_ref, qdd_ref);
      const Eigen::Vector2d target = mean + 1.3 * (q_ref - mean);
      err2 += (q - target).squaredNorm();
      amp_hip = std::max(amp_hip, std::abs(q[0] - mean[0]));
      ++n;
    }
  }
  // Tracks the intended motion: a feedback "human" with 55 ms of delay and an approximate internal
  // model; RMS error 0.17 rad over both joints (mostly the knee near full extension).
  EXPECT_LT(std::sqrt(err2 / n), 0.2);
  EXPECT_GT(amp_hip, 0.3 * 1.15);        // more excursion than the 0.3 rad base pattern
}

// TrackingGains::feedback_delay: the delayed law at t acts on the state of t - delay, i.e. it equals
// the undelayed law fed that older state (the intended motion itself is not delayed).
TEST(Muscles, FeedbackDelayActsOnTheStateOfDelayAgo) {
  const MuscleParams p = DrawMuscleParams(2);
  const IntendedMotion motion = [](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
    q = {0.3 * std::sin(t), -0.6 + 0.4 * std::sin(2 * t)};
    qd = {0.3 * std::cos(t), 0.8 * std::cos(2 * t)};
    qdd = {-0.3 * std::sin(t), -1.6 * std::sin(2 * t)};
  };
  TrackingGains delayed_gains;
  delayed_gains.feedback_delay = 0.060;
  VoluntaryTracking now(p, motion, TrackingGains{}), delayed(p, motion, delayed_gains);
  const double dt = 1e-3;
  auto state = [](int k, Eigen::Vector2d& q, Eigen::Vector2d& qd) {  // a measured state off the intent
    const double t = k * 1e-3;
    q = {0.25 * std::sin(t + 0.2), -0.5 + 0.3 * std::sin(2 * t)};
    qd = {0.25 * std::cos(t + 0.2), 0.6 * std::cos(2 * t)};
  };
  for (int k = 0; k < 300; ++k) {
    Eigen::Vector2d q, qd, q_old, qd_old;
    state(k, q, qd);
    state(std::max(0, k - 60), q_old, qd_old);  // before 60 ms of history: the first sample
    const MuscleVec u = delayed.Excitation(k * dt, q, qd);
    const MuscleVec ref = now.Excitation(k * dt, q_old, qd_old);
    ASSERT_LT((u - ref).cwiseAbs().maxCoeff(), 1e-12) << "step " << k;
  }
}

// The box QP against brute force: for random positive definite problems, the minimiser over every
// choice of free / at-0 / at-1 per variable (3^5 faces, each solved exactly and kept if feasible) is
// what SolveUnitBoxQp returns, from any start.
TEST(Muscles, BoxQpFindsTheExactMinimiser) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, 1);
  using Mat = Eigen::Matrix<double, kNumMuscles, kNumMuscles>;
  for (int trial = 0; trial < 200; ++trial) {
    Mat B;
    for (int i = 0; i < kNumMuscles; ++i)
      for (int j = 0; j < kNumMuscles; ++j) B(i, j) = n(rng);
    // Ill-conditioned like the allocation: a rank-2 torque map plus a small ridge (trial-dependent).
    const Mat H = B.topRows(2).transpose() * B.topRows(2) * 100.0 + (trial % 2 ? 1e-3 : 1.0) * Mat::Identity();
    MuscleVec f;
    for (int i = 0; i < kNumMuscles; ++i) f[i] = 60.0 * n(rng);
    std::array<bool, kNumMuscles> used{};
    for (int i = 0; i < kNumMuscles; ++i) used[i] = trial % 5 != i;  // one muscle unused in 5 of 5 patterns
    const auto objective = [&](const MuscleVec& u) { return 0.5 * u.dot(H * u) - f.dot(u); };
    double best = 1e300;
    MuscleVec best_u = MuscleVec::Zero();
    for (int code = 0; code < 243; ++code) {  // 3^5
      int c = code, state[kNumMuscles];
      for (int i = 0; i < kNumMuscles; ++i) state[i] = c % 3, c /= 3;
      bool skip = false;
      for (int i = 0; i < kNumMuscles; ++i) skip |= !used[i] && state[i] != 1;  // unused: at 0 only
      if (skip) continue;
      MuscleVec u = MuscleVec::Zero();
      std::vector<int> fr;
      for (int i = 0; i < kNumMuscles; ++i) {
        if (state[i] == 2) u[i] = 1.0;
        if (state[i] == 0) fr.push_back(i);
      }
      if (!fr.empty()) {
        Eigen::MatrixXd Hf(fr.size(), fr.size());
        Eigen::VectorXd rhs(fr.size());
        for (size_t a = 0; a < fr.size(); ++a) {
          rhs[a] = f[fr[a]];
          for (int j = 0; j < kNumMuscles; ++j)
            if (state[j] == 2) rhs[a] -= H(fr[a], j);
          for (size_t b = 0; b < fr.size(); ++b) Hf(a, b) = H(fr[a], fr[b]);
        }
        const Eigen::VectorXd x = Hf.ldlt().solve(rhs);
        for (size_t a = 0; a < fr.size(); ++a) u[fr[a]] = x[a];
      }
      if (u.minCoeff() < -1e-12 || u.maxCoeff() > 1 + 1e-12) continue;
      if (objective(u) < best) best = objective(u), best_u = u;
    }
    for (const MuscleVec& start : {MuscleVec::Zero().eval(), MuscleVec::Constant(0.5).eval(), MuscleVec::Ones().eval()}) {
      int iterations = 0;
      const MuscleVec u = SolveUnitBoxQp(H, f, used, start, &iterations);
      EXPECT_LE(iterations, 3 * kNumMuscles) << "trial " << trial;  // cap 4 kNumMuscles^2
      EXPECT_NEAR(objective(u), best, 1e-9 * (1 + std::abs(best))) << "trial " << trial;
      EXPECT_LT((u - best_u).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial;
      for (int i = 0; i < kNumMuscles; ++i) {
        if (!used[i]) {
          EXPECT_EQ(u[i], 0.0);
        }
      }
    }
  }
}

// A knee-only demand with no co-contraction is shared by the synergists in proportion to their alpha
// (the min-norm solution): VM / RF = alpha_VM / alpha_RF for extension, ST / GAS for flexion, as in
// HAL's calibration exercise (scenarios/hal_emg_calibration.cc). 40 sweeps of coordinate descent,
// the solver before, left RF at 0.75 of that share in the seated swing: the swing then used another
// VM / RF mix than the calibration, and HKS05 eq. 2 read the extensor torque ~7 % high.
TEST(Muscles, KneeDemandIsSharedBySynergistsInProportionToAlpha) {
  const MuscleParams p = DrawMuscleParams(3);
  TrackingGains g;
  g.active = {0, 1};
  g.kp = {0, 60};
  g.kd = {0, 0};
  for (double target : {0.4, -0.4}) {
    const IntendedMotion hold = [target](double, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
      q = {1.5707963267948966, -1.5707963267948966 + target};
      qd.setZero();
      qdd.setZero();
    };
    VoluntaryTracking b(p, hold, g);
    const MuscleVec u = b.Excitation(0.0, Eigen::Vector2d(1.5707963267948966, -1.5707963267948966), Eigen::Vector2d::Zero());
    const auto I = [](Muscle m) { return static_cast<int>(m); };
    const Muscle a = target > 0 ? Muscle::kVM : Muscle::kST, c = target > 0 ? Muscle::kRF : Muscle::kGAS;
    ASSERT_GT(u[I(a)], 0.01);
    EXPECT_NEAR(u[I(c)] / u[I(a)], p.alpha(I(c), 1) / p.alpha(I(a), 1), 1e-6) << MuscleName(a);
    // The desired torque is met: 60 N m/rad x 0.4 rad.
    EXPECT_NEAR(ContractionTorque(p, u, {1.5707963267948966, -1.5707963267948966}, {0, 0})[1], 60 * target, 1e-3 * 24);
  }
}

// Co-contraction mix (TrackingGains::cocontraction_synergy): with a knee demand AND co-contraction c,
// the synergy mix keeps every group alpha-proportional (target c alpha / max alpha plus the min-norm
// correction, also alpha-proportional), the mix HKS05 eq. 2 was calibrated with; the uniform mix (every
// muscle at c) does not, which is what shifts a one-electrode-per-group mu^ under co-contraction.
TEST(Muscles, CoContractionSynergyKeepsTheCalibrationMix) {
  const MuscleParams p = DrawMuscleParams(2);
  const auto I = [](Muscle m) { return static_cast<int>(m); };
  const IntendedMotion hold = [](double, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
    q = {1.5707963267948966, -1.5707963267948966 + 0.2};
    qd.setZero();
    qdd.setZero();
  };
  const Eigen::Vector2d q0(1.5707963267948966, -1.5707963267948966), zero(0, 0);
  for (bool synergy : {true, false}) {
    TrackingGains g;
    g.active = {0, 1};
    g.kp = {0, 60};
    g.kd = {0, 0};
    g.cocontraction_synergy = synergy;
    VoluntaryTracking b(p, hold, g, [](double, const Eigen::Vector2d&, const Eigen::Vector2d&) { return 0.1; });
    const MuscleVec u = b.Excitation(0.0, q0, zero);
    for (Muscle m : {Muscle::kVM, Muscle::kRF, Muscle::kST, Muscle::kGAS})  // no bound active
      ASSERT_TRUE(u[I(m)] > 0 && u[I(m)] < 1) << MuscleName(m) << " " << u[I(m)];
    const double ext = u[I(Muscle::kRF)] / u[I(Muscle::kVM)] / (p.alpha(I(Muscle::kRF), 1) / p.alpha(I(Muscle::kVM), 1));
    const double flx = u[I(Muscle::kGAS)] / u[I(Muscle::kST)] / (p.alpha(I(Muscle::kGAS), 1) / p.alpha(I(Muscle::kST), 1));
    std::printf("[muscles] co-contraction 0.1, %s mix: (RF/VM) / (alpha ratio) %.4f, (GAS/ST) / (alpha ratio) %.4f\n",
                synergy ? "synergy" : "uniform", ext, flx);
    if (synergy) {
      EXPECT_NEAR(ext, 1.0, 1e-6);
      EXPECT_NEAR(flx, 1.0, 1e-6);
    } else {  // muscle_seed 2: alpha ratios far from 1, so the uniform mix departs from them
      EXPECT_GT(std::abs(ext - 1) + std::abs(flx - 1), 0.05);
    }
    // Either way the desired torque is met: 60 N m/rad x 0.2 rad.
    EXPECT_NEAR(ContractionTorque(p, u, q0, zero)[1], 12.0, 1e-3 * 12);
  }
}

// ExaggeratedTarget: the amplitude intent unchanged at s0 = 0. With the outward gate, qd* is the
// derivative of q*: central difference, step 1e-5 s, truncation h^2 |q'''| / 6 up to ~3e-6 rad/s
// where the steepest gate (s0 = 0.05) switches within a few ms and qd* reaches 18 rad/s; tolerance
// 1e-6 (1 + |qd*|), while an error in w' would show as O(1). And w takes its limits: 1 moving out,
// 0 coming back, 1/2 at the turning points.
TEST(Muscles, ExaggeratedTargetOutwardGateIsSmoothAndTakesItsLimits) {
  const Eigen::Vector2d mean(0.25, -0.6);
  const auto pattern = [&](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
    const double w = 2 * kPi * 0.5;  // a stride of 2 s with a second harmonic, like a gait pattern
    q = mean + Eigen::Vector2d(0.3 * std::sin(w * t), 0.4 * std::sin(w * t - 1.0) + 0.1 * std::sin(2 * w * t));
    qd = Eigen::Vector2d(0.3 * w * std::cos(w * t), 0.4 * w * std::cos(w * t - 1.0) + 0.2 * w * std::cos(2 * w * t));
    qdd = Eigen::Vector2d(-0.3 * w * w * std::sin(w * t),
                          -0.4 * w * w * std::sin(w * t - 1.0) - 0.4 * w * w * std::sin(2 * w * t));
  };
  const auto target = [&](double t, double s0, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
    Eigen::Vector2d qdd;
    pattern(t, q, qd, qdd);
    ExaggeratedTarget(mean, 2.0, s0, q, qd, qdd);
  };
  for (double t = 0; t < 2.0; t += 0.013) {
    Eigen::Vector2d q, qd, qdd, q0, qd0;
    pattern(t, q, qd, qdd);
    const Eigen::Vector2d qb = q;
    target(t, 0.0, q0, qd0);
    EXPECT_EQ(q0, mean + 2.0 * (qb - mean));  // the amplitude intent, bit for bit
    for (double s0 : {0.05, 0.5, 3.0}) {
      Eigen::Vector2d qs, qds, qp, qm, dummy;
      target(t, s0, qs, qds);
      const double h = 1e-5;
      target(t + h, s0, qp, dummy);
      target(t - h, s0, qm, dummy);
      for (int j = 0; j < 2; ++j) {
        EXPECT_NEAR(qds[j], (qp[j] - qm[j]) / (2 * h), 1e-6 * (1 + std::abs(qds[j]))) << "t " << t << " s0 " << s0 << " joint " << j;
        // Between the pattern (w = 0) and the full exaggeration (w = 1).
        const double lo = std::min(qb[j], mean[j] + 2.0 * (qb[j] - mean[j]));
        const double hi = std::max(qb[j], mean[j] + 2.0 * (qb[j] - mean[j]));
        EXPECT_GE(qs[j], lo - 1e-12);
        EXPECT_LE(qs[j], hi + 1e-12);
      }
    }
  }
  // Limits of w on a pure sine about the mean (x = A sin, qd = A w cos).
  const auto limits = [&](double x, double v, double s0) {
    Eigen::Vector2d q(mean[0] + x, mean[1]), qd(v, 0), qdd(0, 0);
    ExaggeratedTarget(mean, 2.0, s0, q, qd, qdd);
    return (q[0] - mean[0]) / x - 1.0;  // = (gain - 1) w = w
  };
  EXPECT_NEAR(limits(0.3, 1.0, 1e-3), 1.0, 1e-12);   // moving out: full push
  EXPECT_NEAR(limits(0.3, -1.0, 1e-3), 0.0, 1e-12);  // coming back: relaxed onto the pattern
  EXPECT_NEAR(limits(0.3, 0.0, 1e-3), 0.5, 1e-12);   // turning point
  EXPECT_NEAR(limits(-0.3, -1.0, 0.5), 0.5 * (1 + std::tanh(0.3 / 0.5)), 1e-12);  // out on the other side
}

}  // namespace
}  // namespace exotwin
