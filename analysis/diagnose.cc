#include "analysis/diagnose.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "analysis/diagnose_columns.h"
#include "analysis/effects.h"
#include "analysis/generate.h"
#include "analysis/predict.h"
#include "analysis/statistics.h"
#include "model/leg_dynamics.h"
#include "dsp/butterworth.h"
#include "model/input_error.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

constexpr double kBicMargin = 10.0;       // BIC drop needed to name an effect (strong evidence)
constexpr double kMinHeldoutGain = 0.05;  // held-out SSE drop needed (fraction)
constexpr double kMinT = 4.0;             // |coefficient| / standard error
const char* kJoint[2] = {"hip", "knee"};

// Least-squares fit of a column subset from Gram matrices (train and held-out).
struct Fit {
  bool ok = false;
  std::vector<int> cols;
  Eigen::VectorXd coef, se;
  double sse_tr = 0, sse_te = 0, bic = 0;
};

struct Grams {
  Eigen::MatrixXd Gtr, Gte;
  Eigen::VectorXd btr, bte;
  double rrtr = 0, rrte = 0;
  double n_tr = 0, n_eff = 0;
};

Grams MakeGrams(const ColumnBank& b) {
  const Eigen::Index m = static_cast<Eigen::Index>(b.sample.size());
  const Eigen::Index mtr = static_cast<Eigen::Index>(std::count(b.train.begin(), b.train.end(), true));
  const Eigen::Index C = b.X.cols();
  Grams g;
  g.Gtr = Eigen::MatrixXd::Zero(C, C);
  g.Gte = Eigen::MatrixXd::Zero(C, C);
  g.btr = Eigen::VectorXd::Zero(C);
  g.bte = Eigen::VectorXd::Zero(C);
  for (Eigen::Index j = 0; j < 2; ++j) {  // train rows come first in each joint block
    const auto tr = b.X.middleRows(j * m, mtr);
    const auto te = b.X.middleRows(j * m + mtr, m - mtr);
    g.Gtr.selfadjointView<Eigen::Lower>().rankUpdate(tr.transpose());
    g.Gte.selfadjointView<Eigen::Lower>().rankUpdate(te.transpose());
    g.btr += tr.transpose() * b.r.segment(j * m, mtr);
    g.bte += te.transpose() * b.r.segment(j * m + mtr, m - mtr);
    g.rrtr += b.r.segment(j * m, mtr).squaredNorm();
    g.rrte += b.r.segment(j * m + mtr, m - mtr).squaredNorm();
  }
  g.Gtr = g.Gtr.selfadjointView<Eigen::Lower>();
  g.Gte = g.Gte.selfadjointView<Eigen::Lower>();
  g.n_tr = static_cast<double>(2 * mtr);
  return g;
}

Fit FitCols(const Grams& g, std::vector<int> cols) {
  std::sort(cols.begin(), cols.end());
  cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
  Fit f;
  f.cols = cols;
  const int p = static_cast<int>(cols.size());
  if (p == 0) {
    f.ok = true;
    f.sse_tr = g.rrtr, f.sse_te = g.rrte;
    f.bic = g.n_eff * std::log(g.rrtr / g.n_tr);
    return f;
  }
  Eigen::MatrixXd A(p, p), Ate(p, p);
  Eigen::VectorXd bb(p), bte(p);
  for (int a = 0; a < p; ++a) {
    bb[a] = g.btr[cols[a]], bte[a] = g.bte[cols[a]];
    for (int c = 0; c < p; ++c) A(a, c) = g.Gtr(cols[a], cols[c]), Ate(a, c) = g.Gte(cols[a], cols[c]);
  }
  // Conditioning on the column-normalized Gram (near collinearity makes a candidate unusable).
  Eigen::VectorXd d = A.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd An = d.asDiagonal() * A * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(An);
  if (!(es.eigenvalues()[0] > 1e-8 * es.eigenvalues()[p - 1])) return f;
  const Eigen::MatrixXd Ainv = d.asDiagonal() *
                               (es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() *
                                es.eigenvectors().transpose()) *
                               d.asDiagonal();
  f.coef = Ainv * bb;
  f.sse_tr = std::max(1e-300, g.rrtr - 2 * f.coef.dot(bb) + f.coef.dot(A * f.coef));
  f.sse_te = std::max(0.0, g.rrte - 2 * f.coef.dot(bte) + f.coef.dot(Ate * f.coef));
  // Covariance with the residual variance and the autocorrelation length n_tr / n_eff.
  const double s2 = f.sse_tr / (g.n_tr - p) * (g.n_tr / g.n_eff);
  f.se = (Ainv.diagonal() * s2).cwiseMax(0).cwiseSqrt();
  f.bic = g.n_eff * std::log(f.sse_tr / g.n_tr) + p * std::log(g.n_eff);
  f.ok = true;
  return f;
}

// Integrated autocorrelation length (in rows) of the residual after the kitchen-sink fit.
double AutocorrLength(const Eigen::VectorXd& e, size_t m) {
  double worst = 1.0;
  for (int j = 0; j < 2; ++j) {
    const Eigen::VectorXd x = e.segment(j * m, m).array() - e.segment(j * m, m).mean();
    const double v = x.squaredNorm();
    if (v <= 0) continue;
    double tau = 1.0;
    for (size_t lag = 1; lag < std::min<size_t>(m / 4, 2000); ++lag) {
      const double rho = x.head(m - lag).dot(x.tail(m - lag)) / v;
      if (rho < 0.05) break;
      tau += 2 * rho;
    }
    worst = std::max(worst, tau);
  }
  return worst;
}

std::vector<int> Union(const std::vector<const Candidate*>& set) {
  std::vector<int> cols;
  for (const auto* c : set) cols.insert(cols.end(), c->cols.begin(), c->cols.end());
  return cols;
}

double CoefOf(const Fit& f, int col) {
  for (size_t i = 0; i < f.cols.size(); ++i)
    if (f.cols[i] == col) return f.coef[i];
  return 0;
}
double SeOf(const Fit& f, int col) {
  for (size_t i = 0; i < f.cols.size(); ++i)
    if (f.cols[i] == col) return f.se[i];
  return 0;
}

// Physically admissible and significant? (sign constraints of DESIGN.md, |t| on the main column).
bool Admissible(const Candidate& c, const Fit& f) {
  if (!f.ok) return false;
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  if (c.name == "torque_ripple") {
    const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
    return std::hypot(v, b) > kMinT * std::max(se, sb);
  }
  if (c.name == "muscle_activity") {
    for (int col : c.cols)
      if (std::abs(CoefOf(f, col)) > kMinT * SeOf(f, col)) return true;
    return false;
  }
  if ((c.name == "coulomb_friction" || c.name == "backlash" || c.name == "series_compliance" ||
       c.name == "sensor_delay") && !(v > 0))
    return false;
  if (c.name == "series_compliance" && 1.0 / v > 1e6) return false;
  if (c.name == "sensor_gain" && !(v > -0.9)) return false;
  return std::abs(v) > kMinT * se;
}

DiagnosedEffect ToEffect(const Candidate& c, const Fit& f, double g) {
  DiagnosedEffect d;
  Effect& e = d.effect;
  e.name = c.name, e.joint = kJoint[c.joint], e.axis = c.axis;
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  d.ci_lo = v - 1.96 * se, d.ci_hi = v + 1.96 * se;
  e.value = v;
  static const std::map<std::string, std::string> units = {
      {"coulomb_friction", "N m"}, {"viscous_friction", "N m s/rad"}, {"inertia_error", "kg m^2"},
      {"gravity_error", "kg m"}, {"joint_stiffness", "N m/rad"}, {"backlash", "rad"},
      {"series_compliance", "N m/rad"}, {"torque_ripple", "N m"}, {"sensor_offset", "N m"},
      {"sensor_gain", "relative"}, {"sensor_delay", "s"}, {"muscle_activity", "-"}};
  e.unit = units.at(c.name);
  if (c.name == "joint_stiffness") {
    e.fields["q0"] = std::abs(v) > 0 ? CoefOf(f, c.cols[1]) / v : 0.0;
  } else if (c.name == "series_compliance") {
    e.value = 1.0 / v;
    d.ci_lo = v + 1.96 * se > 0 ? 1.0 / (v + 1.96 * se) : 1.0;
    d.ci_hi = v - 1.96 * se > 0 ? 1.0 / (v - 1.96 * se) : 1e6;
  } else if (c.name == "torque_ripple") {
    const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
    e.value = std::hypot(v, b);
    const double sA = e.value > 0 ? std::sqrt(std::pow(v * se, 2) + std::pow(b * sb, 2)) / e.value : 0;
    d.ci_lo = e.value - 1.96 * sA, d.ci_hi = e.value + 1.96 * sA;
    e.fields["cycles_per_rad"] = c.ripple_f;
    e.fields["phase"] = std::atan2(b, v);
  } else if (c.name == "muscle_activity") {
    e.value = 1.0, d.ci_lo = d.ci_hi = 1.0;
    for (size_t k = 0; k < c.cols.size(); ++k)
      if (std::abs(CoefOf(f, c.cols[k])) > 2.0 * SeOf(f, c.cols[k]))
        e.fields["w_" + c.channels[k]] = CoefOf(f, c.cols[k]);
    if (e.fields.empty()) e.fields["w_" + c.channels[0]] = CoefOf(f, c.cols[0]);
  }
  return d;
}

// Weighted SSE of measured - (base tau_R through ApplyEffects(p)) on samples [a, b).
double ExactSse(const LegParams& p, const Kinematics& kin, const std::vector<double> tau_R[2],
                const std::vector<double> meas[2], const double w[2], size_t a, size_t b) {
  Kinematics k;
  k.t.assign(kin.t.begin() + a, kin.t.begin() + b);
  std::vector<double> tr[2], ts[2];
  for (int j = 0; j < 2; ++j) {
    k.q[j].assign(kin.q[j].begin() + a, kin.q[j].begin() + b);
    k.qd[j].assign(kin.qd[j].begin() + a, kin.qd[j].begin() + b);
    k.qdd[j].assign(kin.qdd[j].begin() + a, kin.qdd[j].begin() + b);
    tr[j].assign(tau_R[j].begin() + a, tau_R[j].begin() + b);
  }
  for (const auto& ch : kin.emg) k.emg[ch.first].assign(ch.second.begin() + a, ch.second.begin() + b);
  ApplyEffects(p, k, tr, ts);
  double s = 0;
  const size_t lo = std::min<size_t>(200, (b - a) / 10);  // skip the edges (delay, filters)
  for (int j = 0; j < 2; ++j)
    for (size_t i = lo; i + lo < b - a; ++i) s += std::pow(w[j] * (meas[j][a + i] - ts[j][i]), 2);
  return s;
}

Kinematics Slice(const Kinematics& kin, size_t a, size_t b) {
  Kinematics k;
  k.t.assign(kin.t.begin() + a, kin.t.begin() + b);
  for (int j = 0; j < 2; ++j) {
    k.q[j].assign(kin.q[j].begin() + a, kin.q[j].begin() + b);
    k.qd[j].assign(kin.qd[j].begin() + a, kin.qd[j].begin() + b);
    k.qdd[j].assign(kin.qdd[j].begin() + a, kin.qdd[j].begin() + b);
  }
  for (const auto& ch : kin.emg) k.emg[ch.first].assign(ch.second.begin() + a, ch.second.begin() + b);
  k.derivative_source = kin.derivative_source;
  return k;
}

// Dominant frequency (Hz) of x[a, b) by a direct DFT of a strided copy, 0.05 .. 25 Hz.
double DominantHz(const std::vector<double>& t, const std::vector<double>& x, size_t a, size_t b) {
  const size_t stride = std::max<size_t>(1, (b - a) / 8000);
  std::vector<double> tt, xx;
  double mean = 0;
  for (size_t i = a; i < b; i += stride) tt.push_back(t[i]), xx.push_back(x[i]), mean += x[i];
  mean /= static_cast<double>(xx.size());
  const double T = tt.back() - tt.front();
  const double fmax = std::min(25.0, 0.5 * static_cast<double>(xx.size()) / std::max(T, 1e-9));
  double best = 0, best_f = 0;
  for (double f = std::max(0.05, 1.0 / std::max(T, 1e-9)); f <= fmax; f += 0.5 / std::max(T, 1.0)) {
    double re = 0, im = 0;
    for (size_t i = 0; i < xx.size(); ++i) {
      const double ph = 2 * M_PI * f * tt[i];
      re += (xx[i] - mean) * std::cos(ph), im += (xx[i] - mean) * std::sin(ph);
    }
    if (re * re + im * im > best) best = re * re + im * im, best_f = f;
  }
  return best_f;
}

}  // namespace

Diagnosis Diagnose(const LegParams& params, const MeasuredData& data, const DiagnoseOptions& opt) {
  // EXOTWIN_DIAG_TIMING=1 prints the time of each stage to stderr.
  const bool timing = std::getenv("EXOTWIN_DIAG_TIMING") != nullptr;
  auto t_last = std::chrono::steady_clock::now();
  auto Lap = [&](const char* what) {
    if (!timing) return;
    const auto now = std::chrono::steady_clock::now();
    std::fprintf(stderr, "diagnose: %-22s %8.1f ms\n", what,
                 std::chrono::duration<double, std::milli>(now - t_last).count());
    t_last = now;
  };
  if (data.size() < 200)
    throw InputError(data.source + ": " + std::to_string(data.size()) +
                     " samples, expected at least 200 for a diagnosis (fit and held-out parts)");
  if (!(opt.holdout_fraction >= 0.1 && opt.holdout_fraction <= 0.5))
    throw InputError("holdout fraction: expected 0.1 .. 0.5");
  Diagnosis D;
  D.holdout_fraction = opt.holdout_fraction;
  // The zero-phase derivative filter's start and end transients (about 0.5 s) are not data: trim.
  {
    const Kinematics full = DeriveKinematics(data);
    const double T = full.t.back() - full.t.front();
    const double edge = std::min(0.5, 0.05 * T);
    const size_t a = static_cast<size_t>(
        std::lower_bound(full.t.begin(), full.t.end(), full.t.front() + edge) - full.t.begin());
    const size_t b = static_cast<size_t>(
        std::upper_bound(full.t.begin(), full.t.end(), full.t.back() - edge) - full.t.begin());
    D.kin = Slice(full, a, b);
    D.measured[0].assign(data.tau_hip.begin() + a, data.tau_hip.begin() + b);
    D.measured[1].assign(data.tau_knee.begin() + a, data.tau_knee.begin() + b);
  }
  const Kinematics& kin = D.kin;
  const size_t n = kin.t.size();
  Lap("kinematics");
  const double t_split = kin.t.front() + (1 - opt.holdout_fraction) * (kin.t.back() - kin.t.front());
  D.split = static_cast<size_t>(std::lower_bound(kin.t.begin(), kin.t.end(), t_split) - kin.t.begin());

  // The twin on the whole record: eq. (5)-(7) + P(q) + the model's own effects, which equals
  // predict's MuJoCo inverse dynamics to round-off (tests/integration) at a tenth of the cost; the
  // extended twin's held-out run below is predict itself.
  Plant plant(opt.mjcf.empty() ? ShippedModelFor(params) : opt.mjcf);
  plant.SetParams(params);  // validates the realization
  Prediction base;
  base.t = kin.t;
  for (auto& v : base.tau_R) v.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d tau = ActuatorTorque(params, {kin.q[0][i], kin.q[1][i]},
                                               {kin.qd[0][i], kin.qd[1][i]}, {kin.qdd[0][i], kin.qdd[1][i]});
    base.tau_R[0][i] = tau[0], base.tau_R[1][i] = tau[1];
  }
  {
    std::vector<double> rigid[2] = {base.tau_R[0], base.tau_R[1]};
    ApplyEffects(params, kin, rigid, base.tau_S);  // base.tau_R stays the rigid torque
  }
  std::vector<double> resid[2];
  double w[2];
  for (int j = 0; j < 2; ++j) {
    D.before[j] = base.tau_S[j];
    resid[j].resize(n);
    for (size_t i = 0; i < n; ++i) resid[j][i] = D.measured[j][i] - base.tau_S[j][i];
    double s = 0;
    for (size_t i = 1; i < n; ++i) s += std::pow(resid[j][i] - resid[j][i - 1], 2);
    D.noise[j] = std::max(1e-6, std::sqrt(s / (2.0 * static_cast<double>(n - 1))));
    w[j] = 1.0 / D.noise[j];
  }

  Lap("twin (predict)");
  // Candidates, the kitchen-sink residual (noise structure, ripple search), Gram matrices.
  ColumnBank bank = BuildColumns(params, kin, base.tau_R, base.tau_S, resid, w, D.split, opt.max_fit_rows);
  const size_t m = bank.sample.size();
  {
    Eigen::MatrixXd Gr = Eigen::MatrixXd::Zero(bank.X.cols(), bank.X.cols());
    Gr.selfadjointView<Eigen::Lower>().rankUpdate(bank.X.transpose());
    Gr = Gr.selfadjointView<Eigen::Lower>();
    Gr.diagonal() += 1e-9 * Gr.diagonal().cwiseMax(1e-300);
    const Eigen::VectorXd c = Gr.ldlt().solve(bank.X.transpose() * bank.r);
    const Eigen::VectorXd e = bank.r - bank.X * c;
    // Ripple frequency searched on what the other candidates leave and on the raw residual (a slow
    // ripple, ~1 cycle over the range, is otherwise absorbed by the stiffness/gravity columns).
    AddRippleCandidates(bank, kin, e);
    AddRippleCandidates(bank, kin, bank.r);
  }
  Lap("columns + ripple search");
  // Delay: replace the derivative column by the secant (tau_S(t - d) - tau_S(t)) / d at the single
  // fit's d, twice, so the second-order term is not left for sensor_gain to absorb.
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& c : bank.candidates) {
      if (c.name != "sensor_delay") continue;
      double xr = 0, xx = 0;
      for (size_t k = 0; k < m; ++k) {
        if (!bank.train[k]) continue;
        const double x = bank.X(c.joint * m + k, c.cols[0]);
        xr += x * bank.r[c.joint * m + k], xx += x * x;
      }
      const double d = xx > 0 ? xr / xx : 0;
      if (!(d > 1e-4 && d < 0.5)) continue;
      const int j = c.joint;
      std::vector<double> tq(n);
      for (size_t i = 0; i < n; ++i) tq[i] = kin.t[i] - d;
      const std::vector<double> shifted = Interpolate(kin.t, base.tau_S[j], tq);
      for (size_t k = 0; k < m; ++k) {
        const size_t i = bank.sample[k];
        bank.X(j * m + k, c.cols[0]) = w[j] * (shifted[i] - base.tau_S[j][i]) / d;
      }
    }
  }
  Grams g = MakeGrams(bank);
  {
    // Autocorrelation length of what no candidate explains: kitchen sink incl. ripple.
    Eigen::MatrixXd Gr = g.Gtr + g.Gte;
    Gr.diagonal() += 1e-9 * Gr.diagonal().cwiseMax(1e-300);
    const Eigen::VectorXd c = Gr.ldlt().solve(g.btr + g.bte);
    D.tau_eff = AutocorrLength(bank.r - bank.X * c, m);
    g.n_eff = g.n_tr / D.tau_eff;
  }

  Lap("grams + noise");
  // Scores: baseline, singles, pairs.
  const Fit f0 = FitCols(g, {});
  struct Scored {
    std::vector<const Candidate*> set;
    Fit fit;
    bool admissible;
  };
  std::vector<Scored> singles, pairs;
  for (const auto& c : bank.candidates) {
    Fit f = FitCols(g, c.cols);
    singles.push_back({{&c}, f, Admissible(c, f)});
  }
  auto gain = [&](const Fit& f) { return f0.sse_te > 0 ? 1 - f.sse_te / f0.sse_te : 0.0; };
  auto ok_single = [&](const Scored& s) {
    return s.admissible && s.fit.bic < f0.bic - kBicMargin && gain(s.fit) >= kMinHeldoutGain;
  };
  for (size_t a = 0; a < bank.candidates.size(); ++a)
    for (size_t b = a + 1; b < bank.candidates.size(); ++b) {
      const Candidate& A = bank.candidates[a];
      const Candidate& B = bank.candidates[b];
      if (A.name == B.name && A.joint == B.joint) continue;  // gravity X and Y: one effect at a time
      Fit f = FitCols(g, Union({&A, &B}));
      pairs.push_back({{&A, &B}, f, f.ok && Admissible(A, f) && Admissible(B, f)});
    }
  std::sort(singles.begin(), singles.end(), [](const Scored& x, const Scored& y) {
    return (x.fit.ok ? x.fit.bic : 1e300) < (y.fit.ok ? y.fit.bic : 1e300);
  });
  std::sort(pairs.begin(), pairs.end(), [](const Scored& x, const Scored& y) {
    return (x.fit.ok && x.admissible ? x.fit.bic : 1e300) < (y.fit.ok && y.admissible ? y.fit.bic : 1e300);
  });
  const Scored* chosen = nullptr;
  for (const auto& s : singles)
    if (ok_single(s)) { chosen = &s; break; }
  // Nested candidates (sensor_offset's column is part of joint_stiffness): the extra parameter must
  // earn its own BIC margin and held-out drop (as a second effect must), else the simpler is named.
  if (chosen)
    for (const auto& s : singles) {
      const bool earns = s.fit.bic >= chosen->fit.bic + kBicMargin &&
                         chosen->fit.sse_te <= (1 - kMinHeldoutGain) * s.fit.sse_te;
      if (&s == chosen || !ok_single(s) || earns) continue;
      const auto& big = chosen->set[0]->cols;
      const auto& small = s.set[0]->cols;
      if (small.size() < big.size() &&
          std::all_of(small.begin(), small.end(), [&](int c) {
            return std::find(big.begin(), big.end(), c) != big.end();
          })) {
        chosen = &s;
        break;
      }
    }
  if (chosen && opt.max_effects >= 2 && !pairs.empty() && pairs[0].admissible) {
    const Scored& p = pairs[0];
    const double extra = (chosen->fit.sse_te - p.fit.sse_te) / std::max(chosen->fit.sse_te, 1e-300);
    if (p.fit.bic < chosen->fit.bic - kBicMargin && extra >= kMinHeldoutGain &&
        gain(p.fit) >= kMinHeldoutGain)
      chosen = &p;
  }
  for (size_t i = 0; i < singles.size() && i < 12; ++i)
    D.scores.push_back({singles[i].set[0]->Label(), singles[i].fit.ok ? singles[i].fit.bic - f0.bic : 0,
                        100 * gain(singles[i].fit), &singles[i] == chosen});
  for (size_t i = 0; i < pairs.size() && i < 5; ++i)
    D.scores.push_back({pairs[i].set[0]->Label() + " + " + pairs[i].set[1]->Label(),
                        pairs[i].fit.ok ? pairs[i].fit.bic - f0.bic : 0, 100 * gain(pairs[i].fit),
                        &pairs[i] == chosen});

  // Nearly collinear candidates on this record (first columns, train rows).
  for (size_t a = 0; a < bank.candidates.size(); ++a)
    for (size_t b = a + 1; b < bank.candidates.size(); ++b) {
      const int ca = bank.candidates[a].cols[0], cb = bank.candidates[b].cols[0];
      if (ca == cb) continue;
      const double r = g.Gtr(ca, cb) / std::sqrt(g.Gtr(ca, ca) * g.Gtr(cb, cb) + 1e-300);
      if (std::abs(r) > 0.95)
        D.collinear.push_back(bank.candidates[a].Label() + " ~ " + bank.candidates[b].Label() +
                              " (|cos| = " + std::to_string(std::abs(r)).substr(0, 5) + ")");
    }

  Lap("selection");
  // The extension; exact refinement of the first-order values (delay, backlash, straps).
  D.extended = params;
  if (chosen) {
    for (const Candidate* c : chosen->set) D.effects.push_back(ToEffect(*c, chosen->fit, params.g));
    for (auto& de : D.effects) D.extended.effects.push_back(de.effect);
    const size_t win_b = std::min(D.split, static_cast<size_t>(std::min<double>(D.split, 6000.0)));
    const size_t win_a = 0;
    for (size_t k = 0; k < D.effects.size(); ++k) {
      const std::string& nm = D.effects[k].effect.name;
      if (nm != "sensor_delay" && nm != "backlash" && nm != "series_compliance") continue;
      const size_t idx = params.effects.size() + k;
      const double v0 = D.extended.effects[idx].value;
      auto obj = [&](double v) {
        LegParams p = D.extended;
        p.effects[idx].value = v;
        return ExactSse(p, kin, base.tau_R, D.measured, w, win_a, win_b);
      };
      double lo = 0.6 * v0, hi = 1.6 * v0;
      const double gr = 0.5 * (std::sqrt(5.0) - 1);
      double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo), f1 = obj(x1), f2 = obj(x2);
      for (int it = 0; it < 16; ++it) {
        if (f1 < f2) hi = x2, x2 = x1, f2 = f1, x1 = hi - gr * (hi - lo), f1 = obj(x1);
        else lo = x1, x1 = x2, f1 = f2, x2 = lo + gr * (hi - lo), f2 = obj(x2);
      }
      const double v = 0.5 * (lo + hi);
      D.extended.effects[idx].value = v;
      D.effects[k].effect.value = v;
      D.effects[k].ci_lo *= v / v0, D.effects[k].ci_hi *= v / v0;
    }
    // Share of the held-out residual each effect removes (linear model, leave-one-out).
    for (size_t k = 0; k < chosen->set.size(); ++k) {
      std::vector<const Candidate*> rest;
      for (size_t l = 0; l < chosen->set.size(); ++l)
        if (l != k) rest.push_back(chosen->set[l]);
      const Fit fr = FitCols(g, Union(rest));
      D.effects[k].explained_pct = f0.sse_te > 0 ? 100 * (fr.sse_te - chosen->fit.sse_te) / f0.sse_te : 0;
    }
  }

  Lap("refinement");
  // Extended twin: full record (plots, signature) and the held-out run that gives rmse_after.
  {
    Plant ext_plant(opt.mjcf.empty() ? ShippedModelFor(D.extended) : opt.mjcf);
    ext_plant.SetParams(D.extended);
    // The held-out run starts 1 s early so that its filters (EMG envelope, delay) have settled;
    // only the held-out samples are scored.
    const size_t warm = static_cast<size_t>(
        std::lower_bound(kin.t.begin(), kin.t.end(), kin.t[D.split] - 1.0) - kin.t.begin());
    const Prediction held_w = PredictTorque(ext_plant, Slice(kin, warm, n));
    Prediction held;
    for (int j = 0; j < 2; ++j) {
      held.tau_S[j].assign(held_w.tau_S[j].begin() + (D.split - warm), held_w.tau_S[j].end());
      D.after[j].assign(n, std::nan(""));  // the extended twin is scored on the held-out part only
      std::copy(held.tau_S[j].begin(), held.tau_S[j].end(), D.after[j].begin() + D.split);
    }
    for (int j = 0; j < 2; ++j) {
      double sb = 0, sa = 0;
      for (size_t i = D.split; i < n; ++i) {
        sb += std::pow(D.measured[j][i] - base.tau_S[j][i], 2);
        sa += std::pow(D.measured[j][i] - held.tau_S[j][i - D.split], 2);
      }
      const double cnt = static_cast<double>(n - D.split);
      D.joints[j].rmse_before = std::sqrt(sb / cnt);
      D.joints[j].rmse_after = std::sqrt(sa / cnt);
      D.joints[j].gain_pct =
          D.joints[j].rmse_before > 0 ? 100 * (1 - D.joints[j].rmse_after / D.joints[j].rmse_before) : 0;
    }
  }

  Lap("extended twin");
  // Unexplained structure: 5 Hz low-passed held-out residual of the extended twin vs the noise.
  {
    const double dt = (kin.t.back() - kin.t.front()) / static_cast<double>(n - 1);
    const double fs = 1.0 / dt;
    for (int j = 0; j < 2; ++j) {
      std::vector<double> e(n - D.split);
      for (size_t i = D.split; i < n; ++i) e[i - D.split] = D.measured[j][i] - D.after[j][i];
      std::vector<double> elp = e;
      if (fs > 12) elp = dsp::FiltFilt(dsp::DesignButterworth(2, dsp::BandType::kLowPass, fs, 5.0), e);
      double mean = 0, rms = 0;
      for (double v : elp) mean += v;
      mean /= static_cast<double>(elp.size());
      for (double v : elp) rms += (v - mean) * (v - mean);
      rms = std::sqrt(rms / static_cast<double>(elp.size()));
      const double white_lp = D.noise[j] * std::sqrt(std::min(1.0, 10.0 / fs));
      if (rms > std::max(4.0 * white_lp, 0.05) && rms > 0.15 * D.joints[j].rmse_before) {
        UnexplainedStructure u;
        u.joint = kJoint[j];
        u.rms = rms;
        std::vector<double> full(n, 0.0);
        for (size_t i = D.split; i < n; ++i) full[i] = D.measured[j][i] - D.after[j][i];
        u.dominant_hz = DominantHz(kin.t, full, D.split, n);
        u.corr_q = Pearson(full, kin.q[j], D.split, n);
        u.corr_qd = Pearson(full, kin.qd[j], D.split, n);
        u.corr_qdd = Pearson(full, kin.qdd[j], D.split, n);
        u.corr_t = Pearson(full, kin.t, D.split, n);
        const double cs[4] = {std::abs(u.corr_q), std::abs(u.corr_qd), std::abs(u.corr_qdd), std::abs(u.corr_t)};
        const char* what[4] = {"angle", "velocity", "acceleration", "time (drift)"};
        const int k = static_cast<int>(std::max_element(cs, cs + 4) - cs);
        u.hint = cs[k] > 0.3 ? std::string("follows the ") + what[k]
                             : "not a function of angle, velocity, acceleration or time alone";
        D.unexplained.push_back(u);
      }
    }
  }
  Lap("unexplained");
  std::ostringstream m_os;
  m_os << "time split: fit on the first " << 100 * (1 - opt.holdout_fraction)
       << " %, rmse by the extended twin (predict) on the last " << 100 * opt.holdout_fraction
       << " %; every DESIGN effect per joint as a linearized least-squares candidate (ripple frequency"
          " by grid + golden search; delay, backlash, strap stiffness refined by golden search on the"
          " exact model); selection by BIC (effective sample size from the residual autocorrelation,"
          " margin " << kBicMargin << ") and held-out error (>= " << 100 * kMinHeldoutGain
       << " % drop), |t| > " << kMinT << ", at most " << opt.max_effects << " effects";
  D.method = m_os.str();
  return D;
}

}  // namespace exotwin
