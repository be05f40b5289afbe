// torque_ripple (DESIGN.md "Effects": tau_R += value * sin(2 pi cycles_per_rad q + phase)): its fit row
// and code. The torque fit's candidate is linear in (a, b) = value (cos phase, sin phase) on the columns
// -sin x, -cos x, x = 2 pi f q_j, once the frequency f is found on a target residual; the motion fit's
// candidate is the torque fit's ripple (its frequency), a and b its parameters.
#include <algorithm>
#include <cmath>

#include "core/parallel_for.h"
#include "diagnosis/column_tools.h"
#include "diagnosis/family_rows.h"
#include "diagnosis/motion_fit.h"
#include "dsp/grid_phasors.h"

namespace exotwin {
namespace {

std::string RippleRange(const Effect& e, const PhysicalScale& s) {
  return e.value <= 0.5 * s.tau_max[EffectJoint(e)] ? "" : "ripple beyond half the largest torque";
}

// a sin x + b cos x = A sin(x + phase), A = hypot(a, b), its error propagated.
void RippleEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
  Effect& e = d->effect;
  e.value = std::hypot(v, b);
  const double sA = e.value > 0 ? std::sqrt(std::pow(v * se, 2) + std::pow(b * sb, 2)) / e.value : 0;
  d->ci_lo = e.value - 1.96 * sA, d->ci_hi = e.value + 1.96 * sA;
  e.fields["cycles_per_rad"] = c.ripple_f;
  e.fields["phase"] = std::atan2(b, v);
}

bool RippleSignificant(const Candidate& c, const Fit& f) {
  const double v = CoefOf(f, c.cols[0]), se = SeOf(f, c.cols[0]);
  const double b = CoefOf(f, c.cols[1]), sb = SeOf(f, c.cols[1]);
  return std::hypot(v, b) > kMinT * std::max(se, sb);
}

Effect DrawRipple(Rng& rng, int, bool) {
  Effect e;
  e.value = rng.Uniform(0.2, 1.0);
  e.fields["cycles_per_rad"] = rng.Uniform(2.0, 8.0);
  e.fields["phase"] = rng.Uniform(-M_PI, M_PI);
  return e;
}

// The candidates (sin/cos of 2 pi f q_j) in every bank (one per record of one device, the same
// columns), with f (1 .. 10 cycles/rad) found by grid + golden search on the train rows of `targets`
// pooled.
void AddRippleCandidates(std::vector<ColumnBank>& banks, const std::vector<const Kinematics*>& kins,
                         const std::vector<Eigen::VectorXd>& targets, const FitFamily& self) {
  // The frequency of each joint, searched on the two joints' threads at once (each search reads only).
  double found[2];
  ParallelFor(2, banks[0].threads, [&](size_t jj) {
    const int j = static_cast<int>(jj);
    // The search's rows: at most ~8000 fitting rows per record (every step-th), the angle and the target.
    std::vector<double> q_row, y_row;
    for (size_t r = 0; r < banks.size(); ++r) {
      const ColumnBank& b = banks[r];
      const size_t m = b.sample.size();
      const size_t step = std::max<size_t>(1, m / 8000);
      for (size_t k = 0; k < m; k += step) {
        if (!b.train[k]) continue;
        q_row.push_back(kins[r]->q[j][b.sample[k]]);
        y_row.push_back(targets[r][j * m + k]);
      }
    }
    const size_t N = q_row.size();
    // The rows' phasors exp(i x), x = 2 pi f q, on the grid f = 1, 1.1, .. 10 Hz (dsp::GridPhasors)
    // and at the refinement's frequencies; the residual sum of squares of the target fitted by
    // a sin x + b cos x.
    constexpr int kAnchor = 16;
    dsp::GridPhasors phasors(std::move(q_row), 0.1, kAnchor);
    const std::vector<double>& re = phasors.re();
    const std::vector<double>& im = phasors.im();
    auto sse_of_phasors = [&] {
      double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0, yy = 0;
      for (size_t i = 0; i < N; ++i) {
        const double sn = im[i], c = re[i], y = y_row[i];
        ss += sn * sn, sc += sn * c, cc += c * c, ys += y * sn, yc += y * c, yy += y * y;
      }
      const double det = ss * cc - sc * sc;
      if (det <= 1e-12 * (ss * cc + 1e-300)) return yy;
      const double a = (ys * cc - yc * sc) / det, c2 = (yc * ss - ys * sc) / det;
      return yy - a * ys - c2 * yc;
    };
    auto sse = [&](double f) {
      phasors.At(f);
      return sse_of_phasors();
    };
    double best_f = 1.0, best = 0;
    int g = 0;
    for (double f = 1.0; f <= 10.0 + 1e-9; f += 0.1, ++g) {
      phasors.AtGrid(g, f);
      const double v = sse_of_phasors();
      if (g == 0 || v < best) best = v, best_f = f;
    }
    double lo = best_f - 0.1, hi = best_f + 0.1;
    const double gr = 0.5 * (std::sqrt(5.0) - 1);
    for (int it = 0; it < 24; ++it) {
      const double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo);
      if (sse(x1) < sse(x2)) hi = x2; else lo = x1;
    }
    found[j] = 0.5 * (lo + hi);
  });
  for (int j = 0; j < 2; ++j) {
    const double f = found[j];
    for (size_t r = 0; r < banks.size(); ++r) {
      ColumnBank& b = banks[r];
      const size_t m = b.sample.size();
      // Weight of joint j rows: the joint's constant column holds exactly w_j there.
      const double w = b.X(j * m, b.constant[j]);
      const int c0 = static_cast<int>(b.X.cols());
      b.X.conservativeResize(Eigen::NoChange, c0 + 2);
      b.used = c0 + 2;
      b.X.col(c0).setZero();
      b.X.col(c0 + 1).setZero();
      const size_t n = kins[r]->t.size();
      const double ww[2] = {j == 0 ? w : 0.0, j == 1 ? w : 0.0};
      PendingColumns pc(b);
      std::vector<double> v[2] = {std::vector<double>(n), std::vector<double>(n)};
      ForEachSample(b, n, [&](size_t i) {  // -sin, -cos: joint j's rows (the other joint's are zero)
        const double x = 2 * M_PI * f * kins[r]->q[j][i];
        v[0][i] = -std::sin(x), v[1][i] = -std::cos(x);
      });
      for (int k = 0; k < 2; ++k) SetJointColumn(pc, c0 + k, ww, j, std::move(v[k]));
      pc.Flush();
      Candidate c;
      c.name = self.family->name, c.joint = j, c.cols = {c0, c0 + 1}, c.ripple_f = f;
      b.candidates.push_back(c);
    }
  }
}

// The torque fit's ripples at the joint, each a candidate at its frequency (value a, b in a box of
// half the largest torque).
void RippleMotion(MotionJoint& mj, const FitFamily& self) {
  const std::string name = self.family->name, joint = mj.j == 0 ? "hip" : "knee";
  const double tau = mj.scale.tau;
  for (const DiagnosedEffect& d : *mj.torque_named)
    if (d.effect.name == name && d.effect.joint == joint && !mj.carried(self)) {
      const double f = d.effect.fields.at("cycles_per_rad");
      const int a = mj.add_parameter(self, name + ".sin", {-0.5 * tau, 0.5 * tau, 0.02 * tau}, f);
      mj.add_candidate(self, {a, mj.add_parameter(self, name + ".cos", {-0.5 * tau, 0.5 * tau, 0.02 * tau}, f)});
    }
}

// Parameter k is a (the pair's first: the ripple hypot(a, b) at phase atan2(b, a)) or b (a ripple
// where a is 0).
bool RippleOfValue(const MotionProblem& P, int k, const Eigen::VectorXd& theta, Effect* e) {
  const std::string& kind = P.kind(k);
  const bool first = kind.compare(kind.size() - 4, 4, ".sin") == 0;
  if (!first && theta[k - 1] != 0) return false;
  const double a = first ? theta[k] : 0.0, b = first ? theta[k + 1] : theta[k];
  e->value = first ? std::hypot(a, b) : std::abs(b);
  e->fields["cycles_per_rad"] = P.ripple_f(k);
  e->fields["phase"] = std::atan2(b, a);
  return true;
}

void RippleValues(const Effect& e, const Candidate& cand, Eigen::VectorXd* theta) {
  const double ph = e.fields.count("phase") ? e.fields.at("phase") : 0.0;
  (*theta)[cand.cols[0]] = e.value * std::cos(ph);
  (*theta)[cand.cols[1]] = e.value * std::sin(ph);
}

}  // namespace

FitFamily TorqueRippleRow() {
  FitFamily f = FitRow("torque_ripple", RippleRange, DrawRipple);
  f.to_effect = RippleEffect, f.significant = RippleSignificant;
  f.add_searched_columns = AddRippleCandidates, f.motion_candidates = RippleMotion, f.motion_effect = RippleOfValue;
  f.torque_values = RippleValues;
  return f;
}

}  // namespace exotwin
