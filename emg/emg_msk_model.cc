#include "emg/emg_msk_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/error.h"
#include "emg/emg_torque_model.h"
#include "formats/measured_data.h"

namespace exotwin {

MusculotendonParams EmgMskMuscle::Params() const {
  MusculotendonParams p = nominal;
  p.l_opt = l_opt, p.l_ts = l_ts;
  return p;
}

std::string EmgMskMuscle::Label() const { return synthesized ? MuscleName(muscle) + std::string(" from ") + channel : channel; }
std::string EmgMskMuscle::MuscleLabel() const { return synthesized ? MuscleName(muscle) + std::string(" (synthesized)") : channel; }

namespace {

constexpr int kExtras = 4;  // beta, gamma, offset, passive_scale per joint

// Activation of one channel (emg_torque_model.h: delay, twitch, A-shape).
std::vector<double> Activation(const EmgRecording& rec, const std::string& channel, double delay, double twitch, double A) {
  std::vector<double> u = ChannelEnvelope(rec, channel);
  if (delay != 0) {
    std::vector<double> tq(rec.size());
    for (size_t i = 0; i < tq.size(); ++i) tq[i] = rec.t[i] - delay;
    u = Interpolate(rec.t, u, tq);
  }
  u = TwitchFilter(rec.t, u, twitch);
  for (double& x : u) x = ActivationShape(x, A);
  return u;
}

// The path of every channel on every sample of one recording (parameter-free).
struct Geometry {
  std::vector<std::vector<double>> L, Ld, r[2];  // per channel
};

Geometry GeometryOf(const EmgRecording& rec, const std::vector<EmgMskMuscle>& mus) {
  Geometry g;
  const size_t n = rec.size();
  for (const EmgMskMuscle& m : mus) {
    std::vector<double> L(n), Ld(n), r0(n), r1(n);
    const bool ankle = !rec.q_ankle.empty();
    for (size_t i = 0; i < n; ++i) {
      const MtuKinematics k = MusculotendonKinematics(m.muscle, rec.q[0][i], rec.q[1][i], ankle ? rec.q_ankle[i] : 0.0);
      L[i] = k.length, r0[i] = k.arm[0], r1[i] = k.arm[1];
      // dL/dt = sum dL/dq qd = -sum r qd
      Ld[i] = -(k.arm[0] * rec.qd[0][i] + k.arm[1] * rec.qd[1][i] + (ankle ? k.arm_ankle * rec.qd_ankle[i] : 0.0));
    }
    g.L.push_back(std::move(L)), g.Ld.push_back(std::move(Ld)), g.r[0].push_back(std::move(r0)),
        g.r[1].push_back(std::move(r1));
  }
  return g;
}

// The unit's states on a recording at activations a: force per F_max, normalized fibre length and
// velocity per sample (the elastic tendon's series, or the rigid tendon's state sample by sample; a
// synthesized term's: rigid, active force only, EmgMskMuscle).
TendonSeries UnitStates(const EmgMskMuscle& m, const MusculotendonParams& p, bool elastic, const std::vector<double>& t,
                        const Geometry& g, size_t c, const std::vector<double>& a) {
  TendonSeries s;
  if (elastic && !m.synthesized) {
    ElasticTendonSeries(p, t, g.L[c], a, &s);
    return s;
  }
  const size_t n = a.size();
  s.fibre_length.resize(n), s.fibre_velocity.resize(n), s.force.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const HillState h = RigidTendonState(p, g.L[c][i], g.Ld[c][i]);
    s.force[i] = a[i] * h.active + (m.synthesized ? 0.0 : h.passive);
    s.fibre_length[i] = h.fibre_length, s.fibre_velocity[i] = h.fibre_velocity;
  }
  return s;
}

// Unit-strength moment columns of channel c at both joints: F_max f r_j, f the force per F_max.
void MuscleColumns(const EmgMskMuscle& m, const MusculotendonParams& p, bool elastic, const std::vector<double>& t,
                   const std::vector<double>& a, const Geometry& g, size_t c, std::vector<double> col[2]) {
  const TendonSeries s = UnitStates(m, p, elastic, t, g, c, a);
  const size_t n = a.size();
  col[0].resize(n), col[1].resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double F = m.nominal.f_max * s.force[i];
    col[0][i] = F * g.r[0][c][i], col[1][i] = F * g.r[1][c][i];
  }
}

// One recording in the calibration: its geometry, the activations and columns of the current
// parameters, and the rows fitted / scored per joint.
struct Rec {
  const EmgRecording* rec;
  Geometry geo;
  std::vector<std::vector<double>> act;            // per channel
  std::vector<std::array<std::vector<double>, 2>> col;  // per channel, per joint
  std::vector<char> spike_ok[2];                   // within kSpikeMads of the median (whole recording)
  std::vector<double> passive[2];                  // M_P along each joint (PassiveMomentAlong, the model's range)
};

// Bounded least squares: min |W (X x - tau)|^2 over the fit rows, x = [strength per channel (in
// [lo, hi]), beta, gamma, offset per joint (free)], by the active-set method on the normal equations.
struct Solved {
  Eigen::VectorXd x;
  double sse = 0;
};

Solved SolveBounded(const Eigen::MatrixXd& G, const Eigen::VectorXd& b, double rr, const std::vector<double>& blo,
                    const std::vector<double>& bhi) {
  const int n_bounded = static_cast<int>(blo.size());
  const int C = static_cast<int>(G.rows());
  std::vector<int> state(C, 0);  // 0 free, -1 at the lower bound, +1 at the upper bound
  Eigen::VectorXd x = Eigen::VectorXd::Zero(C);
  auto bound = [&](int k) { return state[k] < 0 ? blo[k] : bhi[k]; };
  for (int iter = 0; iter < 4 * C + 8; ++iter) {
    std::vector<int> fr;
    for (int k = 0; k < C; ++k)
      if (state[k] == 0) fr.push_back(k);
      else x[k] = bound(k);
    if (!fr.empty()) {
      const int F = static_cast<int>(fr.size());
      Eigen::MatrixXd A(F, F);
      Eigen::VectorXd r(F);
      for (int i = 0; i < F; ++i) {
        r[i] = b[fr[i]];
        for (int k = 0; k < C; ++k)
          if (state[k] != 0) r[i] -= G(fr[i], k) * x[k];
        for (int j = 0; j < F; ++j) A(i, j) = G(fr[i], fr[j]);
      }
      A.diagonal().array() += 1e-12 * (A.diagonal().array().abs().maxCoeff() + 1);
      const Eigen::VectorXd xf = A.ldlt().solve(r);
      // Free strengths outside their bounds: clamp the worst and solve again.
      int worst = -1;
      double dv = 0;
      for (int i = 0; i < F; ++i) {
        const int k = fr[i];
        if (k >= n_bounded) continue;
        const double v = std::max(blo[k] - xf[i], xf[i] - bhi[k]);
        if (v > dv) dv = v, worst = i;
      }
      if (worst >= 0) {
        const int k = fr[worst];
        state[k] = xf[worst] < blo[k] ? -1 : 1;
        continue;
      }
      for (int i = 0; i < F; ++i) x[fr[i]] = xf[i];
    }
    // KKT at the bounds: release the bound whose gradient points inside the box most.
    const Eigen::VectorXd grad = G * x - b;
    int rel = -1;
    double gv = 1e-12 * (std::abs(rr) + 1);
    for (int k = 0; k < n_bounded; ++k) {
      const double v = state[k] < 0 ? -grad[k] : state[k] > 0 ? grad[k] : 0;
      if (v > gv) gv = v, rel = k;
    }
    if (rel < 0) break;
    state[rel] = 0;
  }
  Solved s;
  s.x = x;
  s.sse = std::max(0.0, rr - 2 * b.dot(x) + x.dot(G * x));
  return s;
}

class Calibration {
 public:
  Calibration(std::vector<Rec>* recs, std::vector<EmgMskMuscle>* mus, const double w[2], bool elastic)
      : recs_(*recs), mus_(*mus), w_{w[0], w[1]}, elastic_(elastic) {}

  // Fit rows: every row within the spike limit except those of the fold [a, b) of recording `rec`
  // (rec < 0: none left out).
  void LeaveOut(int rec, size_t a, size_t b) { out_rec_ = rec, out_a_ = a, out_b_ = b; }

  void SetActivation(double delay, double twitch, double A) {
    for (Rec& r : recs_) {
      r.act.resize(mus_.size());
      for (size_t c = 0; c < mus_.size(); ++c) {
        // A synthesized term's source is a recorded unit's channel: its activation, already computed.
        const size_t first = FirstOfChannel(c);
        r.act[c] = first < c ? r.act[first] : Activation(*r.rec, mus_[c].channel, delay, twitch, A);
      }
    }
  }
  void SetColumns(size_t c) {
    const MusculotendonParams p = mus_[c].Params();
    for (Rec& r : recs_) {
      r.col.resize(mus_.size());
      std::vector<double> col[2];
      MuscleColumns(mus_[c], p, elastic_, r.rec->t, r.act[c], r.geo, c, col);
      r.col[c][0] = std::move(col[0]), r.col[c][1] = std::move(col[1]);
    }
  }
  void SetAllColumns() {
    for (size_t c = 0; c < mus_.size(); ++c) SetColumns(c);
  }

  Solved Solve() const {
    const int M = static_cast<int>(mus_.size()), C = M + 2 * kExtras;
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(C, C);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(C);
    double rr = 0;
    Eigen::VectorXd x(C);
    for (size_t k = 0; k < recs_.size(); ++k) {
      const Rec& r = recs_[k];
      const EmgRecording& e = *r.rec;
      for (int j = 0; j < 2; ++j) {
        const double w2 = w_[j] * w_[j];
        for (size_t i = 0; i < e.size(); ++i) {
          if (!r.spike_ok[j][i] || (static_cast<int>(k) == out_rec_ && i >= out_a_ && i < out_b_)) continue;
          x.setZero();
          for (int c = 0; c < M; ++c) x[c] = r.col[c][j][i];
          x[M + kExtras * j] = e.q[j][i], x[M + kExtras * j + 1] = e.qd[j][i], x[M + kExtras * j + 2] = 1;
          x[M + kExtras * j + 3] = r.passive[j][i];
          G.selfadjointView<Eigen::Lower>().rankUpdate(x, w2);
          b += w2 * e.tau[j][i] * x;
          rr += w2 * e.tau[j][i] * e.tau[j][i];
        }
      }
    }
    G = G.selfadjointView<Eigen::Lower>();
    std::vector<double> blo(M), bhi(M);
    for (int c = 0; c < M; ++c) blo[c] = mus_[c].strength_lo, bhi[c] = mus_[c].strength_hi;
    return SolveBounded(G, b, rr, blo, bhi);
  }

  // The whole search: delay and A on a grid with the nominal lengths (the global step), then a
  // pattern search (Hooke & Jeeves 1961) of delay, A and every channel's l_ts and l_opt, each in its
  // bounds, the step halving from a quarter of the band to 1/128 of it (the Levenberg-Marquardt step refines).
  void Calibrate(double twitch, double* delay, double* A) {
    for (EmgMskMuscle& m : mus_) m.l_ts = m.nominal.l_ts, m.l_opt = m.nominal.l_opt;
    static const double kA[] = {-2.95, -2.5, -2.0, -1.5, -1.0, -0.5, -0.05};
    double best = std::numeric_limits<double>::infinity();
    for (int di = 1; di <= 10; ++di)
      for (double a : kA) {
        SetActivation(0.01 * di, twitch, a);
        SetAllColumns();
        const double s = Solve().sse;
        if (s < best) best = s, *delay = 0.01 * di, *A = a;
      }
    // Parameters in their bands: [0] delay 10-100 ms, [1] A in (-3, 0), then l_ts, l_opt per channel.
    const size_t P = 2 + 2 * Searched();
    std::vector<double> lo(P), hi(P), x(P);
    lo[0] = 0.01, hi[0] = 0.1, x[0] = *delay;
    lo[1] = -2.999, hi[1] = -0.001, x[1] = std::clamp(*A, lo[1], hi[1]);
    for (size_t c = 0; c < Searched(); ++c) {
      const MusculotendonParams& n = mus_[c].nominal;
      lo[2 + 2 * c] = (1 - kTendonSlackChange) * n.l_ts, hi[2 + 2 * c] = (1 + kTendonSlackChange) * n.l_ts;
      lo[3 + 2 * c] = (1 - kOptimalFibreChange) * n.l_opt, hi[3 + 2 * c] = (1 + kOptimalFibreChange) * n.l_opt;
      x[2 + 2 * c] = n.l_ts, x[3 + 2 * c] = n.l_opt;
    }
    auto apply = [&](size_t k) {
      if (k < 2) {
        SetActivation(x[0], twitch, x[1]);
        SetAllColumns();
        return;
      }
      const size_t c = (k - 2) / 2;
      mus_[c].l_ts = x[2 + 2 * c], mus_[c].l_opt = x[3 + 2 * c];
      SetColumns(c);
    };
    apply(0);
    best = Solve().sse;
    for (double frac = 0.25; frac >= 1.0 / 128; frac /= 2) {
      bool improved = true;
      for (int sweep = 0; sweep < 4 && improved; ++sweep) {
        improved = false;
        for (size_t k = 0; k < P; ++k) {
          const double x0 = x[k], step = frac * (hi[k] - lo[k]);
          for (double dir : {1.0, -1.0}) {
            x[k] = std::clamp(x0 + dir * step, lo[k], hi[k]);
            if (x[k] == x0) continue;
            apply(k);
            const double s = Solve().sse;
            if (s < best) {
              best = s, improved = true;
              break;
            }
            x[k] = x0;
          }
          if (x[k] == x0) apply(k);
        }
      }
    }
    Refine(twitch, lo, hi, &x);
    *delay = x[0], *A = x[1];
    apply(0);
  }

  // Projected Levenberg-Marquardt on every parameter together (the searched ones, the strengths and
  // the remainder), from the pattern search's point: the searched parameters are coupled (two
  // channels on one path trade lengths and strengths), which a one-at-a-time search leaves short of the
  // minimum. Jacobian of the searched parameters by central differences of the columns.
  void Refine(double twitch, const std::vector<double>& lo, const std::vector<double>& hi, std::vector<double>* xp) {
    std::vector<double>& x = *xp;
    const size_t M = mus_.size(), P = x.size(), L = M + 2 * kExtras, N = P + L;
    auto set = [&](const std::vector<double>& v) {
      SetActivation(v[0], twitch, v[1]);
      for (size_t c = 0; c < Searched(); ++c) mus_[c].l_ts = v[2 + 2 * c], mus_[c].l_opt = v[3 + 2 * c];
      SetAllColumns();
    };
    // Columns of every recording at the current parameters (copy).
    using Cols = std::vector<std::vector<std::array<std::vector<double>, 2>>>;
    auto cols = [&]() {
      Cols out;
      for (const Rec& r : recs_) out.push_back(r.col);
      return out;
    };
    Solved lin = Solve();
    double sse = lin.sse;
    double lambda = 1e-3;
    for (int it = 0; it < 15; ++it) {
      const Cols c0 = cols();
      // d columns / d parameter k (central differences), for the searched parameters: delay and A move
      // every channel's columns; a channel's lengths only its own (the others' derivatives left empty).
      std::vector<Cols> dcol(P);
      for (size_t k = 0; k < P; ++k) {
        const double h = k == 0 ? 1e-3 : k == 1 ? 1e-3 : 1e-4 * x[k];
        std::vector<double> v = x;
        if (k < 2) {
          v[k] = x[k] + h;
          set(v);
          Cols up = cols();
          v[k] = x[k] - h;
          set(v);
          const Cols dn = cols();
          for (size_t r = 0; r < up.size(); ++r)
            for (size_t c = 0; c < M; ++c)
              for (int j = 0; j < 2; ++j)
                for (size_t i = 0; i < up[r][c][j].size(); ++i) up[r][c][j][i] = (up[r][c][j][i] - dn[r][c][j][i]) / (2 * h);
          dcol[k] = std::move(up);
          set(x);
          continue;
        }
        const size_t c = (k - 2) / 2;
        auto own = [&](double value) {
          (k % 2 == 0 ? mus_[c].l_ts : mus_[c].l_opt) = value;
          SetColumns(c);
          std::vector<std::array<std::vector<double>, 2>> out;
          for (const Rec& r : recs_) out.push_back(r.col[c]);
          return out;
        };
        auto up = own(x[k] + h);
        const auto dn = own(x[k] - h);
        own(x[k]);
        dcol[k].assign(recs_.size(), std::vector<std::array<std::vector<double>, 2>>(M));
        for (size_t r = 0; r < recs_.size(); ++r) {
          for (int j = 0; j < 2; ++j)
            for (size_t i = 0; i < up[r][j].size(); ++i) up[r][j][i] = (up[r][j][i] - dn[r][j][i]) / (2 * h);
          dcol[k][r][c] = std::move(up[r]);
        }
      }
      // Normal equations of the residual w (tau - sum s_c col_c - extras) in all N parameters.
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(N), static_cast<Eigen::Index>(N));
      Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(N)), J(static_cast<Eigen::Index>(N));
      for (size_t k = 0; k < recs_.size(); ++k) {
        const Rec& r = recs_[k];
        const EmgRecording& e = *r.rec;
        for (int j = 0; j < 2; ++j)
          for (size_t i = 0; i < e.size(); ++i) {
            if (!Fitted(k, j, i)) continue;
            double pred = lin.x[static_cast<Eigen::Index>(M + kExtras * j)] * e.q[j][i] +
                          lin.x[static_cast<Eigen::Index>(M + kExtras * j + 1)] * e.qd[j][i] +
                          lin.x[static_cast<Eigen::Index>(M + kExtras * j + 2)] +
                          lin.x[static_cast<Eigen::Index>(M + kExtras * j + 3)] * r.passive[j][i];
            J.setZero();
            for (size_t c = 0; c < M; ++c) {
              pred += lin.x[static_cast<Eigen::Index>(c)] * c0[k][c][j][i];
              J[static_cast<Eigen::Index>(P + c)] = c0[k][c][j][i];
            }
            J[static_cast<Eigen::Index>(P + M + kExtras * j)] = e.q[j][i];
            J[static_cast<Eigen::Index>(P + M + kExtras * j + 1)] = e.qd[j][i];
            J[static_cast<Eigen::Index>(P + M + kExtras * j + 2)] = 1;
            J[static_cast<Eigen::Index>(P + M + kExtras * j + 3)] = r.passive[j][i];
            for (size_t p = 0; p < P; ++p) {
              double d = 0;
              for (size_t c = 0; c < M; ++c)
                if (!dcol[p][k][c][j].empty()) d += lin.x[static_cast<Eigen::Index>(c)] * dcol[p][k][c][j][i];
              J[static_cast<Eigen::Index>(p)] = d;
            }
            const double w = w_[j], res = e.tau[j][i] - pred;
            H.selfadjointView<Eigen::Lower>().rankUpdate(J, w * w);
            g += w * w * res * J;
          }
      }
      H = H.selfadjointView<Eigen::Lower>();
      bool accepted = false;
      for (int tries = 0; tries < 6 && !accepted; ++tries) {
        Eigen::MatrixXd A = H;
        A.diagonal() += lambda * H.diagonal() + Eigen::VectorXd::Constant(static_cast<Eigen::Index>(N), 1e-12);
        const Eigen::VectorXd d = A.ldlt().solve(g);
        std::vector<double> v = x;
        for (size_t p = 0; p < P; ++p) v[p] = std::clamp(x[p] + d[static_cast<Eigen::Index>(p)], lo[p], hi[p]);
        set(v);
        const Solved s2 = Solve();
        if (s2.sse < sse) {
          x = v, lin = s2, accepted = sse - s2.sse > 1e-9 * sse || true;
          const double gain = sse - s2.sse;
          sse = s2.sse;
          lambda = std::max(lambda / 10, 1e-7);
          if (gain < 1e-7 * sse) it = 100;  // converged
        } else {
          lambda *= 10;
        }
      }
      set(x);
      if (!accepted) break;
    }
  }

  // The first unit driven by unit c's channel.
  size_t FirstOfChannel(size_t c) const {
    size_t f = 0;
    while (mus_[f].channel != mus_[c].channel) ++f;
    return f;
  }

  // The units whose lengths are searched: the recorded ones (the synthesized terms come last and keep
  // their path's nominal lengths: each is a share of one muscle, EmgMskMuscle).
  size_t Searched() const {
    size_t n = 0;
    while (n < mus_.size() && !mus_[n].synthesized) ++n;
    return n;
  }

  bool Fitted(size_t k, int j, size_t i) const {
    return recs_[k].spike_ok[j][i] && !(static_cast<int>(k) == out_rec_ && i >= out_a_ && i < out_b_);
  }


  // Moment at joint j of recording k on samples [a, b) with coefficients x.
  std::vector<double> Predict(const Eigen::VectorXd& x, size_t k, int j, size_t a, size_t b) const {
    const Rec& r = recs_[k];
    const int M = static_cast<int>(mus_.size());
    std::vector<double> p(b - a);
    for (size_t i = a; i < b; ++i) {
      double v = x[M + kExtras * j] * r.rec->q[j][i] + x[M + kExtras * j + 1] * r.rec->qd[j][i] + x[M + kExtras * j + 2] +
                 x[M + kExtras * j + 3] * r.passive[j][i];
      for (int c = 0; c < M; ++c) v += x[c] * r.col[c][j][i];
      p[i - a] = v;
    }
    return p;
  }

 private:
  std::vector<Rec>& recs_;
  std::vector<EmgMskMuscle>& mus_;
  double w_[2];
  bool elastic_;
  int out_rec_ = -1;
  size_t out_a_ = 0, out_b_ = 0;
};

}  // namespace

EmgMskSeries MskSeries(const EmgMskModel& m, const EmgRecording& rec) {
  EmgMskSeries s;
  const size_t n = rec.size();
  for (int j = 0; j < 2; ++j) {
    s.tau[j].assign(n, 0.0);
    s.outside[j].assign(n, 0);
    for (size_t i = 0; i < n; ++i)
      s.tau[j][i] = m.beta[j] * rec.q[j][i] + m.gamma[j] * rec.qd[j][i] + m.offset[j] +
                    (m.passive_scale[j] != 0 ? m.passive_scale[j] * PassiveMomentAlong(j, rec.q[0][i], rec.q[1][i], m.q_lo, m.q_hi) : 0.0);
  }
  const Geometry g = GeometryOf(rec, m.muscles);
  for (size_t c = 0; c < m.muscles.size(); ++c) {
    const EmgMskMuscle& mu = m.muscles[c];
    const MusculotendonParams p = mu.Params();
    const std::vector<double> a = Activation(rec, mu.channel, m.delay, m.twitch, m.a_shape);
    TendonSeries st = UnitStates(mu, p, m.elastic_tendon, rec.t, g, c, a);
    std::vector<double> F(n), &l = st.fibre_length, &v = st.fibre_velocity;
    for (size_t i = 0; i < n; ++i) {
      F[i] = mu.strength * p.f_max * st.force[i];
      const bool out = l[i] < mu.fibre_lo || l[i] > mu.fibre_hi || v[i] < mu.velocity_lo || v[i] > mu.velocity_hi;
      for (int j = 0; j < 2; ++j) {
        s.tau[j][i] += F[i] * g.r[j][c][i];
        if (out && ActionSign(mu.muscle, j) != 0) s.outside[j][i] = 1;
      }
    }
    s.force.push_back(std::move(F)), s.fibre.push_back(std::move(l)), s.velocity.push_back(std::move(v));
  }
  return s;
}

EmgMskModel FitEmgMsk(const std::vector<const EmgRecording*>& recs, double twitch, const EmgMskFitOptions& opt) {
  if (recs.empty()) throw InputError("emg fit: no recording");
  const auto start = std::chrono::steady_clock::now();
  EmgMskModel model;
  model.twitch = twitch;
  const EmgRecording& r0 = *recs[0];
  for (size_t c = 0; c < r0.channels.size(); ++c) {
    EmgMskMuscle m;
    m.channel = r0.channels[c], m.muscle = r0.muscle[c];
    const MusculotendonParams path = ScaledMusculotendon(m.muscle, GenericMusculotendon(m.muscle));
    m.nominal = path;
    MusculotendonParams own;
    if (GenericMusculotendon(m.channel, &own)) m.nominal.f_max = own.f_max, m.nominal.name = own.name;
    m.l_opt = m.nominal.l_opt, m.l_ts = m.nominal.l_ts;
    const auto sb = opt.strength_bounds.find(m.channel);
    if (sb != opt.strength_bounds.end()) m.strength_lo = sb->second[0], m.strength_hi = sb->second[1];
    model.muscles.push_back(m);
  }
  // The recordings' missing muscles, each synthesized from every recorded channel (EmgMskMuscle).
  if (opt.synthesize_missing) {
    const size_t recorded = model.muscles.size();
    for (const std::string& name : r0.missing) {
      Muscle mu;
      if (!MuscleByName(name, &mu)) continue;
      for (size_t c = 0; c < recorded; ++c) {
        EmgMskMuscle m;
        m.channel = model.muscles[c].channel, m.muscle = mu, m.synthesized = true;
        m.nominal = ScaledMusculotendon(mu, GenericMusculotendon(mu));
        m.l_opt = m.nominal.l_opt, m.l_ts = m.nominal.l_ts;
        m.strength_lo = kSynthesizedStrengthLo, m.strength_hi = kStrengthHi;
        model.muscles.push_back(m);
      }
    }
  }
  std::vector<Rec> rs;
  double w[2];
  for (int j = 0; j < 2; ++j) {
    double s = 0, ss = 0, n = 0;
    for (const EmgRecording* r : recs)
      for (size_t i : WithinSpikeLimit(r->tau[j], 0, r->size())) s += r->tau[j][i], ss += r->tau[j][i] * r->tau[j][i], n += 1;
    const double var = n > 1 ? (ss - s * s / n) / (n - 1) : 0;
    if (!(var > 0)) throw InputError(r0.source + ": a joint moment is constant");
    w[j] = 1 / std::sqrt(var);
  }
  // The calibration's angle range (the passive moment is continued along its tangent outside it).
  for (int j = 0; j < 2; ++j) {
    model.q_lo[j] = std::numeric_limits<double>::infinity(), model.q_hi[j] = -std::numeric_limits<double>::infinity();
    for (const EmgRecording* r : recs)
      for (double q : r->q[j]) model.q_lo[j] = std::min(model.q_lo[j], q), model.q_hi[j] = std::max(model.q_hi[j], q);
  }
  for (const EmgRecording* r : recs) {
    if (!r->has_moments()) throw InputError(r->source + ": no joint moments to fit (--moments)");
    Rec x;
    for (int j = 0; j < 2; ++j) {
      x.passive[j].resize(r->size());
      for (size_t i = 0; i < r->size(); ++i) x.passive[j][i] = PassiveMomentAlong(j, r->q[0][i], r->q[1][i], model.q_lo, model.q_hi);
    }
    x.rec = r;
    x.geo = GeometryOf(*r, model.muscles);
    for (int j = 0; j < 2; ++j) {
      x.spike_ok[j].assign(r->size(), 0);
      for (size_t i : WithinSpikeLimit(r->tau[j], 0, r->size())) x.spike_ok[j][i] = 1;
    }
    rs.push_back(std::move(x));
  }
  const int M = static_cast<int>(model.muscles.size());
  // The calibration on every sample.
  model.elastic_tendon = opt.elastic_tendon;
  Calibration cal(&rs, &model.muscles, w, model.elastic_tendon);
  cal.Calibrate(twitch, &model.delay, &model.a_shape);
  // Cross-validation: each fold predicted by the strengths and remainder fitted on the others, the
  // searched parameters (delay, A, lengths) kept (as the linear form's folds keep its delays).
  if (opt.cross_validate) {
    struct Fold {
      size_t rec, a, b;
    };
    std::vector<Fold> folds;
    if (recs.size() >= 2) {
      for (size_t k = 0; k < recs.size(); ++k) folds.push_back({k, 0, recs[k]->size()});
    } else {
      const size_t n = r0.size(), K = static_cast<size_t>(std::max(2, opt.blocks));
      for (size_t f = 0; f < K; ++f) folds.push_back({0, f * n / K, (f + 1) * n / K});
    }
    std::vector<double> meas[2], pred[2];
    for (const Fold& f : folds) {
      cal.LeaveOut(static_cast<int>(f.rec), f.a, f.b);
      const Solved s = cal.Solve();
      for (int j = 0; j < 2; ++j) {
        const std::vector<double> p = cal.Predict(s.x, f.rec, j, f.a, f.b);
        for (size_t i = f.a; i < f.b; ++i)
          if (rs[f.rec].spike_ok[j][i]) meas[j].push_back(recs[f.rec]->tau[j][i]), pred[j].push_back(p[i - f.a]);
      }
    }
    cal.LeaveOut(-1, 0, 0);
    for (int j = 0; j < 2; ++j) {
      std::vector<size_t> idx(meas[j].size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
      ScoreSamples(meas[j], pred[j], idx, &model.r2_cv[j], &model.rms_cv[j]);
    }
  }
  const Solved s = cal.Solve();
  for (int c = 0; c < M; ++c) model.muscles[static_cast<size_t>(c)].strength = s.x[c];
  for (int j = 0; j < 2; ++j)
    model.beta[j] = s.x[M + kExtras * j], model.gamma[j] = s.x[M + kExtras * j + 1], model.offset[j] = s.x[M + kExtras * j + 2],
    model.passive_scale[j] = s.x[M + kExtras * j + 3];
  for (EmgMskMuscle& m : model.muscles)
    m.fibre_lo = m.velocity_lo = std::numeric_limits<double>::infinity(),
    m.fibre_hi = m.velocity_hi = -std::numeric_limits<double>::infinity();
  model.present = true;
  double reach[2] = {0, 0}, reach_rec[2] = {0, 0}, total[2] = {0, 0};
  std::vector<double> meas[2], pred[2];
  for (size_t k = 0; k < recs.size(); ++k) {
    const EmgMskSeries ser = MskSeries(model, *recs[k]);
    // Every unit at full activation, and at its recorded activation (the calibration's).
    std::vector<TendonSeries> full, recorded;
    const std::vector<double> ones(recs[k]->size(), 1.0);
    std::map<Muscle, std::vector<double>> synthesized;  // sum_k s_k a_k per synthesized muscle
    for (size_t c = 0; c < model.muscles.size(); ++c) {
      const EmgMskMuscle& m = model.muscles[c];
      const std::vector<double> a = Activation(*recs[k], m.channel, model.delay, model.twitch, model.a_shape);
      full.push_back(UnitStates(m, m.Params(), model.elastic_tendon, recs[k]->t, rs[k].geo, c, ones));
      recorded.push_back(UnitStates(m, m.Params(), model.elastic_tendon, recs[k]->t, rs[k].geo, c, a));
      if (!m.synthesized) continue;
      std::vector<double>& sum = synthesized[m.muscle];
      sum.resize(a.size(), 0.0);
      for (size_t i = 0; i < a.size(); ++i) sum[i] += m.strength * a[i];
    }
    for (const auto& [mu, sum] : synthesized)
      for (double v : sum) model.synthesized_peak = std::max(model.synthesized_peak, v);
    for (size_t c = 0; c < model.muscles.size(); ++c) {
      EmgMskMuscle& m = model.muscles[c];
      const auto l = std::minmax_element(ser.fibre[c].begin(), ser.fibre[c].end());
      const auto v = std::minmax_element(ser.velocity[c].begin(), ser.velocity[c].end());
      m.fibre_lo = std::min(m.fibre_lo, *l.first), m.fibre_hi = std::max(m.fibre_hi, *l.second);
      m.velocity_lo = std::min(m.velocity_lo, *v.first), m.velocity_hi = std::max(m.velocity_hi, *v.second);
    }
    for (int j = 0; j < 2; ++j)
      for (size_t i = 0; i < recs[k]->size(); ++i) {
        if (!rs[k].spike_ok[j][i]) continue;
        const double tau = recs[k]->tau[j][i];
        meas[j].push_back(tau), pred[j].push_back(ser.tau[j][i]);
        // Every muscle pulling along tau's direction at its largest strength, at full activation and
        // at its recorded one.
        double M_dir = 0, M_rec = 0;
        for (size_t c = 0; c < model.muscles.size(); ++c) {
          const EmgMskMuscle& m = model.muscles[c];
          if (m.synthesized) continue;  // what the recorded muscles reach
          const double arm = m.strength_hi * m.nominal.f_max * rs[k].geo.r[j][c][i];
          if (arm * full[c].force[i] * tau > 0) M_dir += std::abs(arm * full[c].force[i]);
          if (arm * recorded[c].force[i] * tau > 0) M_rec += std::abs(arm * recorded[c].force[i]);
        }
        reach[j] += std::min(std::abs(tau), M_dir), reach_rec[j] += std::min(std::abs(tau), M_rec), total[j] += std::abs(tau);
      }
  }
  for (int j = 0; j < 2; ++j) {
    model.reachable_share[j] = total[j] > 0 ? reach[j] / total[j] : 0;
    model.reachable_share_recorded[j] = total[j] > 0 ? reach_rec[j] / total[j] : 0;
    std::vector<size_t> idx(meas[j].size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    double rms;
    ScoreSamples(meas[j], pred[j], idx, &model.r2_fit[j], &rms);
  }
  model.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return model;
}

}  // namespace exotwin
