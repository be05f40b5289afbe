// Muscle model of the twin's human: see muscles.h for conventions, units and the paper equations.
#include "sim/muscles.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

namespace exotwin {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Action signs, rows in Muscle order, columns hip / knee (HJ15 eq. 23-24 in the EXOwheel convention).
constexpr int kSign[kNumMuscles][2] = {
    {-1, 0},   // GMAX: hip extensor
    {0, +1},   // VM:   knee extensor (knee extension = +th2)
    {+1, +1},  // RF:   hip flexor, knee extensor
    {-1, -1},  // ST:   hip extensor, knee flexor
    {0, -1},   // GAS:  knee flexor
};

double Clip01(double x) { return std::min(1.0, std::max(0.0, x)); }

// Normal draw of mean/sd, redrawn while below 20 % of the mean (keeps signs physical).
double DrawPositive(MuscleRng& z, double mean, double sd) {
  for (int i = 0; i < 100; ++i) {
    const double v = mean + sd * z.Normal();
    if (v >= 0.2 * mean) return v;
  }
  return 0.2 * mean;
}

}  // namespace

const char* MuscleName(Muscle m) {
  switch (m) {
    case Muscle::kGMAX: return "GMAX";
    case Muscle::kVM: return "VM";
    case Muscle::kRF: return "RF";
    case Muscle::kST: return "ST";
    case Muscle::kGAS: return "GAS";
  }
  return "?";
}

bool MuscleByName(const std::string& name, Muscle* m) {
  for (int i = 0; i < kNumMuscles; ++i)
    if (name == MuscleName(MuscleAt(i))) return *m = MuscleAt(i), true;
  return false;
}

std::vector<std::string> EmgChannelNames() {
  std::vector<std::string> names;
  for (int c = 0; c < kNumMuscles; ++c) names.push_back(MuscleName(MuscleAt(c)));
  return names;
}

int ActionSign(Muscle m, int joint) { return kSign[static_cast<int>(m)][joint]; }

MuscleParams PaperMeanMuscleParams() {
  MuscleParams p;
  const auto G = [](Muscle m) { return static_cast<int>(m); };
  // alpha: HJ15 eq. 25 text, x100 (per % MVC -> per fraction of MVC, see muscles.h).
  p.alpha(G(Muscle::kRF), 0) = 188;
  p.alpha(G(Muscle::kGMAX), 0) = 108;
  p.alpha(G(Muscle::kST), 0) = 170;
  p.alpha(G(Muscle::kVM), 1) = 253;
  p.alpha(G(Muscle::kRF), 1) = 89;
  p.alpha(G(Muscle::kST), 1) = 291;
  p.alpha(G(Muscle::kGAS), 1) = 151;
  // Table 7, identified rows (10^-3 /deg, 10^-3 /(deg/s)).
  p.beta = {BetaFromPerDeg(3.27e-3), BetaFromPerDeg(2.44e-3)};
  p.gamma = {GammaFromPerDegPerS(1.45e-3), GammaFromPerDegPerS(0.92e-3)};
  return p;
}

MuscleParams DrawMuscleParams(uint64_t seed) {
  MuscleRng z(MixSeed(seed ^ 0x6d75736373ULL));  // "muscs"
  MuscleParams p;
  const auto G = [](Muscle m) { return static_cast<int>(m); };
  p.alpha(G(Muscle::kRF), 0) = 100 * DrawPositive(z, 1.88, 0.76);
  p.alpha(G(Muscle::kGMAX), 0) = 100 * DrawPositive(z, 1.08, 0.42);
  p.alpha(G(Muscle::kST), 0) = 100 * DrawPositive(z, 1.70, 0.83);
  p.alpha(G(Muscle::kVM), 1) = 100 * DrawPositive(z, 2.53, 0.77);
  p.alpha(G(Muscle::kRF), 1) = 100 * DrawPositive(z, 0.89, 0.37);
  p.alpha(G(Muscle::kST), 1) = 100 * DrawPositive(z, 2.91, 1.12);
  p.alpha(G(Muscle::kGAS), 1) = 100 * DrawPositive(z, 1.51, 0.35);
  p.beta[0] = BetaFromPerDeg(1e-3 * DrawPositive(z, 3.27, 1.53));
  p.beta[1] = BetaFromPerDeg(1e-3 * DrawPositive(z, 2.44, 1.31));
  p.gamma[0] = GammaFromPerDegPerS(1e-3 * DrawPositive(z, 1.45, 0.57));
  p.gamma[1] = GammaFromPerDegPerS(1e-3 * DrawPositive(z, 0.92, 0.35));
  p.tau_act *= 0.8 + 0.4 * z.Uniform();
  p.tau_deact *= 0.8 + 0.4 * z.Uniform();
  p.emd *= 0.8 + 0.4 * z.Uniform();
  return p;
}

double ForceFactor(int s, double beta, double gamma, double q, double q_c, double qd) {
  const double f = 1.0 + s * (beta * (q - q_c) - gamma * qd);
  return std::max(0.0, f);
}

Eigen::Vector2d ContractionTorque(const MuscleParams& p, const MuscleVec& a, const Eigen::Vector2d& q,
                                  const Eigen::Vector2d& qd) {
  Eigen::Vector2d tau(0, 0);
  for (int j = 0; j < 2; ++j) {
    for (int m = 0; m < kNumMuscles; ++m) {
      const int s = kSign[m][j];
      if (s == 0) continue;
      tau[j] += s * p.alpha(m, j) * a[m] *
                ForceFactor(s, p.beta[j], p.gamma[j], q[j], p.theta_c[j], qd[j]);
    }
  }
  return tau;
}

MuscleModel::MuscleModel(const MuscleParams& params, double dt) : p_(params), dt_(dt) {
  if (!(dt > 0)) throw std::invalid_argument("MuscleModel: dt must be > 0");
  const long n = std::lround(std::max(0.0, p_.emd) / dt);
  delay_.assign(static_cast<size_t>(n), MuscleVec::Zero());
}

void MuscleModel::Reset() {
  e_.setZero();
  a_.setZero();
  for (auto& v : delay_) v.setZero();
  head_ = 0;
}

void MuscleModel::Step(const MuscleVec& u) {
  const double k_act = std::exp(-dt_ / p_.tau_act), k_deact = std::exp(-dt_ / p_.tau_deact);
  for (int m = 0; m < kNumMuscles; ++m) {
    const double um = Clip01(u[m]);
    const double k = um > e_[m] ? k_act : k_deact;  // exact step of the first-order lag
    e_[m] = um + (e_[m] - um) * k;
  }
  if (delay_.empty()) {
    a_ = e_;
  } else {
    a_ = delay_[head_];  // e from emd ago
    delay_[head_] = e_;
    head_ = (head_ + 1) % delay_.size();
  }
}

MuscleTorques MuscleModel::Torques(const Eigen::Vector2d& q, const Eigen::Vector2d& qd) const {
  MuscleTorques t;
  t.contraction = ContractionTorque(p_, a_, q, qd);
  for (int j = 0; j < 2; ++j) {
    double E = 0, F = 0;
    for (int m = 0; m < kNumMuscles; ++m) {
      if (kSign[m][j] > 0) E += p_.alpha(m, j) * a_[m];
      if (kSign[m][j] < 0) F += p_.alpha(m, j) * a_[m];
    }
    const double S = 2 * std::min(E, F);
    t.K[j] = p_.K0[j] + p_.cK[j] * S;
    t.D[j] = p_.D0[j] + p_.cD[j] * S;
    t.viscoelastic[j] = -t.D[j] * qd[j] - t.K[j] * (q[j] - p_.q_rest[j]);
  }
  return t;
}

// ------------------------------------------------------------------------------------------------
MuscleVec ContractionProgramme::Excitation(double t, const Eigen::Vector2d&, const Eigen::Vector2d&) {
  MuscleVec u = MuscleVec::Zero();
  for (const auto& b : blocks_) {
    const double x = t - b.t_start;
    if (x <= 0 || x >= 2 * b.ramp + b.hold) continue;
    double w = 1.0;
    if (x < b.ramp) w = x / b.ramp;
    else if (x > b.ramp + b.hold) w = (2 * b.ramp + b.hold - x) / b.ramp;
    u += w * b.peak;
  }
  return u.cwiseMax(0.0).cwiseMin(1.0);
}

double ContractionProgramme::duration() const {
  double end = 0;
  for (const auto& b : blocks_) end = std::max(end, b.t_start + 2 * b.ramp + b.hold);
  return end;
}

ContractionProgramme IsometricProgramme(int joint, int n, double lo, double hi, double cocontraction,
                                        uint64_t seed, double t0, double rest) {
  MuscleRng z(MixSeed(seed ^ 0x69736f6dULL));  // "isom"
  std::vector<ContractionBlock> blocks;
  double t = t0;
  for (int k = 0; k < n; ++k) {
    ContractionBlock b;
    b.t_start = t;
    b.ramp = 0.8 + 0.6 * z.Uniform();
    b.hold = 1.5 + 1.0 * z.Uniform();
    const int dir = (k % 2 == 0) ? +1 : -1;  // flexion first at the hip (+), extension at the knee
    for (int m = 0; m < kNumMuscles; ++m) {
      const int s = kSign[m][joint];
      if (s == 0) continue;
      const double level = lo + (hi - lo) * z.Uniform();  // independent per muscle: identifiable
      b.peak[m] = (s == dir) ? level : cocontraction * level * (0.5 + z.Uniform());
    }
    blocks.push_back(b);
    t += 2 * b.ramp + b.hold + rest;
  }
  return ContractionProgramme(std::move(blocks));
}

ContractionProgramme MvcProgramme(Muscle m, int trials, double t0, double rest) {
  std::vector<ContractionBlock> blocks;
  for (int k = 0; k < trials; ++k) {
    ContractionBlock b;
    b.ramp = 0.5;
    b.hold = 3.0;
    b.t_start = t0 + k * (2 * b.ramp + b.hold + rest);
    b.peak[static_cast<int>(m)] = 1.0;
    blocks.push_back(b);
  }
  return ContractionProgramme(std::move(blocks));
}

// ------------------------------------------------------------------------------------------------
VoluntaryTracking::VoluntaryTracking(const MuscleParams& p, IntendedMotion motion, TrackingGains gains,
                                     CoContraction cocontraction, FeedForward ff)
    : p_(p), motion_(std::move(motion)), g_(gains), cc_(std::move(cocontraction)), ff_(std::move(ff)) {
  if (!g_.cocontraction_synergy) return;
  for (int j = 0; j < 2; ++j)
    for (int m = 0; m < kNumMuscles; ++m) {
      if (kSign[m][j] == 0) continue;
      double group_max = 0;
      for (int n = 0; n < kNumMuscles; ++n)
        if (kSign[n][j] == kSign[m][j]) group_max = std::max(group_max, p_.alpha(n, j));
      cc_share_(m, j) = group_max > 0 ? p_.alpha(m, j) / group_max : 1.0;
    }
}

MuscleVec VoluntaryTracking::Excitation(double t, const Eigen::Vector2d& q_now,
                                        const Eigen::Vector2d& qd_now) {
  Eigen::Vector2d q = q_now, qd = qd_now;
  if (g_.feedback_delay > 0) {  // the newest sample at least feedback_delay old (the first before)
    sensed_.push_back({t, q_now, qd_now});
    while (sensed_.size() > 1 && sensed_[1].t <= t - g_.feedback_delay + 1e-12) sensed_.pop_front();
    q = sensed_.front().q;
    qd = sensed_.front().qd;
  }
  Eigen::Vector2d qs(0, 0), qds(0, 0), qdds(0, 0);
  motion_(t, qs, qds, qdds);
  const Eigen::Vector2d ff = ff_ ? ff_(t, q, qd) : Eigen::Vector2d(0, 0);
  const double cc = cc_ ? cc_(t, q, qd) : 0.0;
  // Torque map of the muscles at the active joints (rows), HJ15 eq. 23-24 at q = q_c.
  Eigen::Matrix<double, 2, kNumMuscles> A = Eigen::Matrix<double, 2, kNumMuscles>::Zero();
  MuscleVec target = MuscleVec::Zero();
  std::array<bool, kNumMuscles> used{};
  for (int j = 0; j < 2; ++j) {
    tau_d_[j] = 0;
    if (g_.active[j] <= 0) continue;
    tau_d_[j] = g_.inertia[j] * qdds[j] + g_.kp[j] * (qs[j] - q[j]) + g_.kd[j] * (qds[j] - qd[j]) + ff[j];
    for (int m = 0; m < kNumMuscles; ++m) {
      if (kSign[m][j] == 0) continue;
      A(j, m) = kSign[m][j] * p_.alpha(m, j);
      // A muscle of two active joints takes the larger of its two shares.
      const double c = cc * cc_share_(m, j);
      target[m] = used[m] ? std::max(target[m], c) : c;
      used[m] = true;
    }
  }
  // Allocation: min |A u - tau_d|^2 + lambda |u - cc|^2, 0 <= u <= 1, solved exactly (SolveUnitBoxQp).
  // lambda is small against alpha^2, so the torque is met whenever the box allows; among the
  // solutions the one nearest the co-contraction level is taken (min-norm: synergists in proportion
  // to their alpha), which spreads the effort over the agonists and lets the biarticular RF and ST be
  // balanced by the monoarticular muscles. (Until session 3 this was 40 sweeps of coordinate descent,
  // which does not converge along the null space of A when lambda is small: it left the effort on the
  // first muscle of each group, VM over RF and ST over GAS, not the documented optimum.)
  const double lambda = 1e-3 * std::max(1.0, A.squaredNorm() / kNumMuscles);
  const Eigen::Matrix<double, kNumMuscles, kNumMuscles> H =
      A.transpose() * A + lambda * Eigen::Matrix<double, kNumMuscles, kNumMuscles>::Identity();
  const MuscleVec f = A.transpose() * tau_d_ + lambda * target;
  return SolveUnitBoxQp(H, f, used, target);
}

MuscleVec SolveUnitBoxQp(const Eigen::Matrix<double, kNumMuscles, kNumMuscles>& H, const MuscleVec& f,
                         const std::array<bool, kNumMuscles>& used, const MuscleVec& start, int* iterations) {
  enum State { kFree, kLow, kHigh, kUnused };
  std::array<State, kNumMuscles> st{};
  MuscleVec u = MuscleVec::Zero();
  for (int m = 0; m < kNumMuscles; ++m) {
    if (!used[m]) {
      st[m] = kUnused;
      continue;
    }
    u[m] = Clip01(start[m]);
    st[m] = u[m] <= 0 ? kLow : (u[m] >= 1 ? kHigh : kFree);
  }
  // Each iteration either drops a bound with a negative multiplier or moves to a point with a lower
  // objective (adding the blocking bound); the method is finite, a few iterations per variable.
  constexpr int kMaxIterations = 4 * kNumMuscles * kNumMuscles;
  for (int iter = 0; iter < kMaxIterations; ++iter) {
    if (iterations) *iterations = iter + 1;
    const MuscleVec g = H * u - f;  // gradient
    int idx[kNumMuscles], n = 0;
    for (int m = 0; m < kNumMuscles; ++m)
      if (st[m] == kFree) idx[n++] = m;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kNumMuscles, kNumMuscles> Hf(n, n);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kNumMuscles, 1> gf(n);
    for (int a = 0; a < n; ++a) {
      gf[a] = g[idx[a]];
      for (int b = 0; b < n; ++b) Hf(a, b) = H(idx[a], idx[b]);
    }
    MuscleVec p = MuscleVec::Zero();
    if (n > 0) {
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kNumMuscles, 1> pf = Hf.ldlt().solve(-gf);
      for (int a = 0; a < n; ++a) p[idx[a]] = pf[a];
    }
    if (p.cwiseAbs().maxCoeff() <= 1e-10) {  // activation units: rounding of g is ~1e-12 here
      // Stationary on the working set: optimal if every active bound's multiplier is >= 0.
      int worst = -1;
      double most_negative = -1e-12 * (1 + f.cwiseAbs().maxCoeff());
      for (int m = 0; m < kNumMuscles; ++m) {
        const double mult = st[m] == kLow ? g[m] : (st[m] == kHigh ? -g[m] : 0.0);
        if (mult < most_negative) most_negative = mult, worst = m;
      }
      if (worst < 0) return u;
      st[worst] = kFree;
      continue;
    }
    double step = 1.0;
    int blocking = -1;
    for (int a = 0; a < n; ++a) {
      const int m = idx[a];
      if (p[m] < 0 && -u[m] / p[m] < step) step = -u[m] / p[m], blocking = m;
      if (p[m] > 0 && (1 - u[m]) / p[m] < step) step = (1 - u[m]) / p[m], blocking = m;
    }
    u += step * p;
    if (blocking >= 0) {
      st[blocking] = p[blocking] < 0 ? kLow : kHigh;
      u[blocking] = p[blocking] < 0 ? 0.0 : 1.0;
    }
  }
  return u;  // at the cap (not reached in tests/sim/muscles_test.cc): a feasible point
}

void ExaggeratedTarget(const Eigen::Vector2d& mean, double gain, double outward_gate, Eigen::Vector2d& q,
                       Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
  if (outward_gate <= 0) {  // amplitude intent: the pattern scaled about its mean
    q = mean + gain * (q - mean);
    qd *= gain;
    qdd *= gain;
    return;
  }
  // q* = q_b + (gain - 1) w x, x = q_b - mean, w = (1 + tanh(p / s0)) / 2, p = x qd_b;
  // qd* = qd_b + (gain - 1)(w qd_b + w' x), w' = (1 - tanh^2) / (2 s0) (qd_b^2 + x qdd_b);
  // qdd* keeps (gain - 1) w qdd_b only (w'' dropped: the gait runner's feed-forward inertia is 0).
  for (int j = 0; j < 2; ++j) {
    const double x = q[j] - mean[j], th = std::tanh(x * qd[j] / outward_gate);
    const double w = 0.5 * (1 + th);
    const double w_dot = 0.5 * (1 - th * th) / outward_gate * (qd[j] * qd[j] + x * qdd[j]);
    q[j] += (gain - 1) * w * x;
    qd[j] += (gain - 1) * (w * qd[j] + w_dot * x);
    qdd[j] += (gain - 1) * w * qdd[j];
  }
}

ExaggeratedGait::ExaggeratedGait(const MuscleParams& p, IntendedMotion base, Eigen::Vector2d mean,
                                 double gain, double t_active, double cocontraction,
                                 TrackingGains gains, double outward_gate)
    : t_active_(t_active),
      tracking_(
          p,
          [base = std::move(base), mean, gain, outward_gate](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd,
                                                             Eigen::Vector2d& qdd) {
            base(t, q, qd, qdd);
            ExaggeratedTarget(mean, gain, outward_gate, q, qd, qdd);
          },
          gains, [cocontraction](double, const Eigen::Vector2d&, const Eigen::Vector2d&) {
            return cocontraction;
          }) {}

MuscleVec ExaggeratedGait::Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) {
  if (t < t_active_) return MuscleVec::Zero();
  return tracking_.Excitation(t, q, qd);
}

void KneeSwingBehaviour::Intended(double t, double freq, Eigen::Vector2d& q, Eigen::Vector2d& qd,
                                  Eigen::Vector2d& qdd) {
  // HAL targets +1.0 / -0.3 rad: centre 0.35, amplitude 0.65; th2 = th_HAL - pi/2.
  const double w = 2 * kPi * freq;
  q = {kPi / 2, -kPi / 2 + 0.35 + 0.65 * std::sin(w * t)};
  qd = {0, 0.65 * w * std::cos(w * t)};
  qdd = {0, -0.65 * w * w * std::sin(w * t)};
}

TrackingGains KneeSwingBehaviour::KneeSwingGains() {
  TrackingGains g;
  g.kp = {0, 60};
  g.kd = {0, 6};
  g.inertia = {0, 0.25};
  g.active = {0, 1};
  return g;
}

KneeSwingBehaviour::KneeSwingBehaviour(const MuscleParams& p, double freq, double cc_up,
                                       double cc_down, double mgl_internal, TrackingGains gains)
    : tracking_(
          p,
          [freq](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
            Intended(t, freq, q, qd, qdd);
          },
          gains,
          [cc_up, cc_down](double, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) {
            const double th_hal = q[1] + kPi / 2;
            return (th_hal > 0 && qd[1] < 0) ? cc_down : cc_up;
          },
          [mgl_internal](double, const Eigen::Vector2d& q, const Eigen::Vector2d&) {
            // Gravity pulls the shank towards hanging: extensor torque mgl sin(th_HAL) holds it.
            return Eigen::Vector2d(0, mgl_internal * std::sin(q[1] + kPi / 2));
          }) {}

MuscleVec KneeSwingBehaviour::Excitation(double t, const Eigen::Vector2d& q, const Eigen::Vector2d& qd) {
  return tracking_.Excitation(t, q, qd);
}

}  // namespace exotwin
