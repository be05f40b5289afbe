#include "controller/trajectory.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/data_dir.h"
#include "core/error.h"
#include "core/file_text.h"
#include "core/rng.h"
#include "core/units.h"
#include "dsp/derivatives.h"

namespace exotwin::controller {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

bool Finite(double x) { return std::isfinite(x); }

// Quintic smoothstep w(s) = 10 s^3 - 15 s^4 + 6 s^5 and its derivatives in s, s in [0, 1].
void Smoothstep(double s, double* w, double* dw, double* ddw) {
  const double s2 = s * s, s3 = s2 * s;
  *w = s3 * (10.0 - 15.0 * s + 6.0 * s2);
  *dw = 30.0 * s2 * (1.0 - 2.0 * s + s2);
  *ddw = 60.0 * s * (1.0 - 3.0 * s + 2.0 * s2);
}

}  // namespace

// ---------------------------------------------------------------- FourierSeries

FourierSeries::FourierSeries(double c0, double f0, std::vector<Term> terms)
    : c0_(c0), f0_(f0), terms_(std::move(terms)) {
  if (!(Finite(f0) && f0 > 0)) throw InputError("FourierSeries: f0 must be > 0 Hz");
  if (!Finite(c0)) throw InputError("FourierSeries: c0 must be finite");
  for (const Term& t : terms_) {
    if (t.k < 1) throw InputError("FourierSeries: harmonic number must be >= 1");
    if (!Finite(t.a) || !Finite(t.b)) throw InputError("FourierSeries: coefficients must be finite");
  }
  std::stable_sort(terms_.begin(), terms_.end(), [](const Term& x, const Term& y) { return x.k < y.k; });
}

JointSetpoint FourierSeries::Eval(double t) const {
  // Phase reduced to one period first so that accuracy does not degrade for large t.
  const double cycles = t * f0_;
  const double phase = kTwoPi * (cycles - std::floor(cycles));
  const double w0 = kTwoPi * f0_;
  JointSetpoint out{c0_, 0.0, 0.0};
  // sin/cos of k * phase by the angle-addition recurrence from one sincos (terms_ is sorted by k at
  // construction); the rounding error grows like k eps, below 1e-14 for the k <= 20 used here.
  const double s1 = std::sin(phase), c1 = std::cos(phase);
  double sk = 0.0, ck = 1.0;  // k = 0
  int k = 0;
  for (const Term& term : terms_) {
    while (k < term.k) {
      const double sn = sk * c1 + ck * s1;
      ck = ck * c1 - sk * s1;
      sk = sn;
      ++k;
    }
    const double w = term.k * w0;
    out.q += term.a * sk + term.b * ck;
    out.qd += w * (term.a * ck - term.b * sk);
    out.qdd -= w * w * (term.a * sk + term.b * ck);
  }
  return out;
}

double FourierSeries::DerivativeBound(int n) const {
  double sum = 0;
  for (const Term& term : terms_)
    sum += std::pow(kTwoPi * term.k * f0_, n) * std::hypot(term.a, term.b);
  return sum;
}

// ---------------------------------------------------------------- ExcitationSpec

ExcitationSpec ExcitationSpec::PaperHip() {
  ExcitationSpec s;
  s.q_min = 5.0 * kRadPerDeg;
  s.q_max = 40.0 * kRadPerDeg;
  s.qd_max = 120.0 * kRadPerDeg;
  s.qdd_max = 1000.0 * kRadPerDeg;
  return s;
}

ExcitationSpec ExcitationSpec::PaperKnee() {
  ExcitationSpec s;
  s.q_min = -70.0 * kRadPerDeg;
  s.q_max = -5.0 * kRadPerDeg;
  s.qd_max = 165.0 * kRadPerDeg;
  s.qdd_max = 1500.0 * kRadPerDeg;
  return s;
}

// ---------------------------------------------------------------- HarmonicTrajectory

HarmonicTrajectory::HarmonicTrajectory(FourierSeries series) : series_(std::move(series)) {}

JointSetpoint HarmonicTrajectory::At(double t) const { return series_.Eval(t); }

HarmonicTrajectory::Extremes HarmonicTrajectory::BoundExtremes(const FourierSeries& s) {
  constexpr int kGrid = 20000;
  const double period = 1.0 / s.f0();
  const double dt = period / kGrid;
  Extremes e{1e300, -1e300, 0.0, 0.0};
  for (int i = 0; i < kGrid; ++i) {
    const JointSetpoint p = s.Eval(i * dt);
    e.q_min = std::min(e.q_min, p.q);
    e.q_max = std::max(e.q_max, p.q);
    e.qd_abs_max = std::max(e.qd_abs_max, std::abs(p.qd));
    e.qdd_abs_max = std::max(e.qdd_abs_max, std::abs(p.qdd));
  }
  // Between grid points an extremum of f exceeds the sampled one by at most max|f''| dt^2 / 8
  // (Taylor expansion about the true extremum, where f' = 0).
  const double pad = dt * dt / 8.0;
  e.q_min -= s.DerivativeBound(2) * pad;
  e.q_max += s.DerivativeBound(2) * pad;
  e.qd_abs_max += s.DerivativeBound(3) * pad;
  e.qdd_abs_max += s.DerivativeBound(4) * pad;
  return e;
}

HarmonicTrajectory HarmonicTrajectory::Design(const ExcitationSpec& spec, uint64_t seed) {
  auto bad = [](const std::string& what) { throw InputError("ExcitationSpec: " + what); };
  if (!(Finite(spec.q_min) && Finite(spec.q_max) && spec.q_min < spec.q_max))
    bad("q_min < q_max required (rad)");
  if (!(Finite(spec.qd_max) && spec.qd_max > 0)) bad("qd_max must be > 0 rad/s");
  if (!(Finite(spec.qdd_max) && spec.qdd_max > 0)) bad("qdd_max must be > 0 rad/s^2");
  if (!(Finite(spec.f0_hz) && spec.f0_hz > 0)) bad("f0_hz must be > 0");
  if (spec.k_min < 1 || spec.k_max < spec.k_min + 1)
    bad("need 1 <= k_min < k_max (two harmonics at least, for the rest constraints)");
  const double eps = 1e-9;
  if (spec.k_min * spec.f0_hz < spec.band_lo_hz - eps || spec.k_max * spec.f0_hz > spec.band_hi_hz + eps)
    bad("harmonics k f0 must lie in [band_lo_hz, band_hi_hz]");
  if (!(spec.fill > 0 && spec.fill <= 1)) bad("fill must be in (0, 1]");

  Rng rng(seed);
  const int n = spec.k_max - spec.k_min + 1;
  std::vector<double> a(n), b(n);
  for (int i = 0; i < n; ++i) {
    const int k = spec.k_min + i;
    a[i] = (2.0 * rng.Uniform() - 1.0) / k;
    b[i] = (2.0 * rng.Uniform() - 1.0) / k;
  }
  // Start at rest: project onto sum_k k a_k = 0 (qd(0) = 0) and sum_k k^2 b_k = 0 (qdd(0) = 0),
  // minimal-norm correction x <- x - (c.x / c.c) c.
  double ca = 0, cc = 0, db = 0, dd = 0;
  for (int i = 0; i < n; ++i) {
    const double k = spec.k_min + i;
    ca += k * a[i];
    cc += k * k;
    db += k * k * b[i];
    dd += k * k * k * k;
  }
  std::vector<FourierSeries::Term> terms(n);
  for (int i = 0; i < n; ++i) {
    const double k = spec.k_min + i;
    terms[i] = {spec.k_min + i, a[i] - ca / cc * k, b[i] - db / dd * k * k};
  }
  const FourierSeries unit(0.0, spec.f0_hz, terms);
  const Extremes e = BoundExtremes(unit);
  const double range = e.q_max - e.q_min;
  if (!(range > 0)) bad("degenerate draw (zero excursion)");
  const double scale = spec.fill * std::min({(spec.q_max - spec.q_min) / range,
                                              spec.qd_max / e.qd_abs_max,
                                              spec.qdd_max / e.qdd_abs_max});
  for (auto& t : terms) {
    t.a *= scale;
    t.b *= scale;
  }
  const double offset = 0.5 * (spec.q_min + spec.q_max) - scale * 0.5 * (e.q_min + e.q_max);
  FourierSeries series(offset, spec.f0_hz, std::move(terms));

  // Verification of the scaled result (independent of the algebra above).
  const Extremes v = BoundExtremes(series);
  if (v.q_min < spec.q_min || v.q_max > spec.q_max || v.qd_abs_max > spec.qd_max ||
      v.qdd_abs_max > spec.qdd_max)
    bad("internal: designed trajectory violates its limits");
  return HarmonicTrajectory(std::move(series));
}

// ---------------------------------------------------------------- Hold, Jointwise, FadeIn

HoldTrajectory::HoldTrajectory(double q) : q_(q) {
  if (!Finite(q)) throw InputError("HoldTrajectory: q must be finite");
}

JointwiseTrajectory::JointwiseTrajectory(std::shared_ptr<const JointTrajectory> hip,
                                         std::shared_ptr<const JointTrajectory> knee)
    : hip_(std::move(hip)), knee_(std::move(knee)) {
  if (!hip_ || !knee_) throw InputError("JointwiseTrajectory: both joint trajectories required");
}

void JointwiseTrajectory::Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const {
  *hip = hip_->At(t);
  *knee = knee_->At(t);
}

FadeInTrajectory::FadeInTrajectory(std::shared_ptr<const LegTrajectory> inner, double fade_s)
    : inner_(std::move(inner)), fade_s_(fade_s) {
  if (!inner_) throw InputError("FadeInTrajectory: inner trajectory required");
  if (!(Finite(fade_s) && fade_s > 0)) throw InputError("FadeInTrajectory: fade_s must be > 0 s");
  inner_->Sample(0.0, &hip0_, &knee0_);
}

void FadeInTrajectory::Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const {
  if (t >= fade_s_) {
    inner_->Sample(t, hip, knee);
    return;
  }
  if (!(t > 0)) {  // before the start (or NaN-free t <= 0): at rest at the start pose
    *hip = {hip0_.q, 0.0, 0.0};
    *knee = {knee0_.q, 0.0, 0.0};
    return;
  }
  JointSetpoint h, k;
  inner_->Sample(t, &h, &k);
  double w, dw, ddw;
  Smoothstep(t / fade_s_, &w, &dw, &ddw);
  dw /= fade_s_;
  ddw /= fade_s_ * fade_s_;
  // Product rule on q0 + w (q_in - q0).
  auto blend = [&](const JointSetpoint& in, double q0) {
    const double e = in.q - q0;
    return JointSetpoint{q0 + w * e, dw * e + w * in.qd, ddw * e + 2.0 * dw * in.qd + w * in.qdd};
  };
  *hip = blend(h, hip0_.q);
  *knee = blend(k, knee0_.q);
}

// ---------------------------------------------------------------- GaitTrajectory

void GaitTrajectory::AnglesFromMarkers(double hip_x, double hip_y, double knee_x, double knee_y,
                                       double ankle_x, double ankle_y, double* th1, double* th2) {
  // Segment angles from the downward vertical, positive when the distal marker is ahead (+x).
  const double thigh = std::atan2(knee_x - hip_x, hip_y - knee_y);
  const double shank = std::atan2(ankle_x - knee_x, knee_y - ankle_y);
  *th1 = thigh;
  *th2 = shank - thigh;  // shank behind the thigh line = flexion = negative
}

std::string GaitTrajectory::DefaultWinterPath() {
  return DataPath("data/WinterTableA1.txt");
}

namespace {

// Detects the stride period as the lag (in frames, refined by a parabola through the mismatch at
// lag-1, lag, lag+1) that best maps the (hip, knee) angle curves onto themselves.
double DetectPeriodFrames(const std::vector<double>& hip, const std::vector<double>& knee,
                          const std::string& path) {
  const int n = static_cast<int>(hip.size());
  const int min_overlap = std::max(10, n / 5);
  const int lag_lo = std::max(2, n / 4), lag_hi = n - min_overlap;
  if (lag_hi <= lag_lo + 2)
    throw InputError(path + ": too few frames to detect the stride period; set data_stride_period_s");
  auto mismatch = [&](int lag) {
    double s = 0;
    for (int i = 0; i + lag < n; ++i) {
      const double dh = hip[i + lag] - hip[i], dk = knee[i + lag] - knee[i];
      s += dh * dh + dk * dk;
    }
    return s / (n - lag);
  };
  int best = lag_lo;
  double best_e = mismatch(lag_lo);
  for (int lag = lag_lo + 1; lag <= lag_hi; ++lag) {
    const double e = mismatch(lag);
    if (e < best_e) { best_e = e; best = lag; }
  }
  // A real repetition gives a mismatch of a few degrees at most (both joints together).
  const double limit = std::pow(5.0 * kRadPerDeg, 2);
  if (best == lag_lo || best == lag_hi || best_e > limit)
    throw InputError(path + ": no repeating stride found in the recording; set data_stride_period_s");
  const double em = mismatch(best - 1), ep = mismatch(best + 1);
  const double den = em - 2.0 * best_e + ep;
  const double shift = den > 0 ? 0.5 * (em - ep) / den : 0.0;
  return best + std::clamp(shift, -0.5, 0.5);
}

// Least-squares periodic Fourier fit y(t) ~ c0 + sum_k a_k sin(k w t) + b_k cos(k w t).
FourierSeries FitFourier(const std::vector<double>& t, const std::vector<double>& y, double f0,
                         int harmonics, double* rms) {
  const int n = static_cast<int>(t.size());
  Eigen::MatrixXd A(n, 2 * harmonics + 1);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    A(i, 0) = 1.0;
    for (int k = 1; k <= harmonics; ++k) {
      A(i, 2 * k - 1) = std::sin(kTwoPi * k * f0 * t[i]);
      A(i, 2 * k) = std::cos(kTwoPi * k * f0 * t[i]);
    }
    b(i) = y[i];
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);
  *rms = std::sqrt((A * x - b).squaredNorm() / n);
  std::vector<FourierSeries::Term> terms;
  for (int k = 1; k <= harmonics; ++k) terms.push_back({k, x(2 * k - 1), x(2 * k)});
  return FourierSeries(x(0), f0, std::move(terms));
}

// Output series: time-scaled to the new period, excursion scaled about the mean, then offset.
FourierSeries Rescale(const FourierSeries& s, double f0_out, double scale, double offset) {
  std::vector<FourierSeries::Term> terms = s.terms();
  for (auto& t : terms) {
    t.a *= scale;
    t.b *= scale;
  }
  return FourierSeries(s.c0() + offset, f0_out, std::move(terms));
}

}  // namespace

GaitTrajectory GaitTrajectory::FromWinterFile(const std::string& path, const GaitSpec& spec) {
  auto bad_spec = [](const std::string& what) { throw InputError("GaitSpec: " + what); };
  if (!(Finite(spec.stride_period_s) && spec.stride_period_s > 0)) bad_spec("stride_period_s must be > 0");
  if (spec.harmonics < 1 || spec.harmonics > 30) bad_spec("harmonics must be in 1..30");
  if (!(Finite(spec.data_stride_period_s) && spec.data_stride_period_s >= 0))
    bad_spec("data_stride_period_s must be >= 0 (0 = detect)");
  if (!Finite(spec.phase_origin_s)) bad_spec("phase_origin_s must be finite");
  if (!Finite(spec.hip_offset) || !Finite(spec.knee_offset)) bad_spec("offsets must be finite");
  if (!(Finite(spec.amplitude_scale) && spec.amplitude_scale > 0)) bad_spec("amplitude_scale must be > 0");

  std::istringstream in(ReadTextFile(path, "Winter marker table", "a text marker table"));
  std::vector<double> time, hip, knee;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '\'' || line[first] == '#') continue;
    std::istringstream ss(line);
    double v[12];
    for (int c = 0; c < 12; ++c) {
      if (!(ss >> v[c]) || !Finite(v[c]))
        throw InputError(path + ":" + std::to_string(line_no) + ": expected at least 12 numbers " +
                         "(FRAME TIME RIB x y HIP x y KNEE x y FIBULA x y ANKLE x y), column " +
                         std::to_string(c + 1) + " is missing or not a number");
    }
    if (!time.empty() && !(v[1] > time.back()))
      throw InputError(path + ":" + std::to_string(line_no) + ": TIME must increase strictly");
    double th1, th2;
    AnglesFromMarkers(v[4], v[5], v[6], v[7], v[10], v[11], &th1, &th2);
    time.push_back(v[1]);
    hip.push_back(th1);
    knee.push_back(th2);
  }
  const int n = static_cast<int>(time.size());
  if (n < 2 * spec.harmonics + 2)
    throw InputError(path + ": " + std::to_string(n) + " frames are too few for " +
                     std::to_string(spec.harmonics) + " harmonics");

  GaitTrajectory g;
  if (spec.data_stride_period_s > 0) {
    g.data_period_s_ = spec.data_stride_period_s;
  } else {
    const double dt = (time.back() - time.front()) / (n - 1);
    g.data_period_s_ = DetectPeriodFrames(hip, knee, path) * dt;
  }
  const double span = (time.back() - time.front()) * n / (n - 1.0);  // frames cover n intervals
  if (span < g.data_period_s_ * (1.0 - 1e-6))
    throw InputError(path + ": the recording is shorter than one stride");
  std::vector<double> tau(n);
  for (int i = 0; i < n; ++i) tau[i] = time[i] - spec.phase_origin_s;
  const double f_data = 1.0 / g.data_period_s_;
  const FourierSeries hip_fit = FitFourier(tau, hip, f_data, spec.harmonics, &g.rms_hip_);
  const FourierSeries knee_fit = FitFourier(tau, knee, f_data, spec.harmonics, &g.rms_knee_);
  const double f_out = 1.0 / spec.stride_period_s;
  g.hip_ = Rescale(hip_fit, f_out, spec.amplitude_scale, spec.hip_offset);
  g.knee_ = Rescale(knee_fit, f_out, spec.amplitude_scale, spec.knee_offset);
  return g;
}

void GaitTrajectory::Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const {
  *hip = hip_.Eval(t);
  *knee = knee_.Eval(t);
}

// ---------------------------------------------------------------- TabulatedTrajectory

TabulatedTrajectory::TabulatedTrajectory(double dt, const std::vector<double>& q_hip,
                                         const std::vector<double>& q_knee, Extend extend, double cutoff_hz)
    : dt_(dt), extend_(extend) {
  if (!(Finite(dt) && dt > 0)) throw InputError("TabulatedTrajectory: dt must be > 0 s");
  if (q_hip.size() != q_knee.size() || q_hip.size() < 2)
    throw InputError("TabulatedTrajectory: hip and knee need the same number of samples, at least 2");
  for (size_t i = 0; i < q_hip.size(); ++i)
    if (!Finite(q_hip[i]) || !Finite(q_knee[i]))
      throw InputError("TabulatedTrajectory: sample " + std::to_string(i) + " is not finite");
  if (!(Finite(cutoff_hz) && cutoff_hz > 0 && cutoff_hz < 0.5 / dt))
    throw InputError("TabulatedTrajectory: the derivative cutoff " + std::to_string(cutoff_hz) +
                     " Hz must lie in (0, " + std::to_string(0.5 / dt) + ") Hz, below the samples' Nyquist frequency");
  const size_t n = q_hip.size();
  const std::vector<double>* in[2] = {&q_hip, &q_knee};
  for (int j = 0; j < 2; ++j) {
    if (extend == Extend::kLoop) {
      std::vector<double> three;
      three.reserve(3 * n);
      for (int c = 0; c < 3; ++c) three.insert(three.end(), in[j]->begin(), in[j]->end());
      const dsp::Derivatives d = dsp::ZeroPhaseDerivatives(three, dt, cutoff_hz);
      q_[j].assign(d.filtered.begin() + n, d.filtered.begin() + 2 * n);
      qd_[j].assign(d.first.begin() + n, d.first.begin() + 2 * n);
      qdd_[j].assign(d.second.begin() + n, d.second.begin() + 2 * n);
    } else {
      dsp::Derivatives d = dsp::ZeroPhaseDerivatives(*in[j], dt, cutoff_hz);
      q_[j] = std::move(d.filtered);
      qd_[j] = std::move(d.first);
      qdd_[j] = std::move(d.second);
    }
  }
}

double TabulatedTrajectory::Duration() const {
  const double n = static_cast<double>(size());
  return extend_ == Extend::kLoop ? n * dt_ : (n - 1.0) * dt_;
}

JointSetpoint TabulatedTrajectory::At(int joint, size_t i, size_t j, double s) const {
  // Cubic Hermite basis on [0, 1] and its derivative (per unit s).
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  const double q0 = q_[joint][i], q1 = q_[joint][j], v0 = qd_[joint][i], v1 = qd_[joint][j];
  const double a0 = qdd_[joint][i], a1 = qdd_[joint][j];
  return {h00 * q0 + h10 * dt_ * v0 + h01 * q1 + h11 * dt_ * v1,
          h00 * v0 + h10 * dt_ * a0 + h01 * v1 + h11 * dt_ * a1,
          a0 + s * (a1 - a0)};
}

void TabulatedTrajectory::Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const {
  const size_t n = size();
  if (!(t > 0)) {
    *hip = {q_[0][0], 0.0, 0.0};
    *knee = {q_[1][0], 0.0, 0.0};
    return;
  }
  if (extend_ == Extend::kHold && t >= Duration()) {
    *hip = {q_[0][n - 1], 0.0, 0.0};
    *knee = {q_[1][n - 1], 0.0, 0.0};
    return;
  }
  double u = t / dt_;
  if (extend_ == Extend::kLoop) u -= std::floor(u / static_cast<double>(n)) * static_cast<double>(n);
  const size_t i = std::min(static_cast<size_t>(u), n - 1);
  const size_t j = i + 1 < n ? i + 1 : 0;  // kHold never reaches i = n - 1 here
  const double s = std::clamp(u - static_cast<double>(i), 0.0, 1.0);
  *hip = At(0, i, j, s);
  *knee = At(1, i, j, s);
}

}  // namespace exotwin::controller
