#include "emg/emg_diagnose.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "diagnosis/diagnose_select.h"
#include "dsp/butterworth.h"
#include "formats/number_text.h"
#include "core/error.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

const char* kJoint[2] = {"hip", "knee"};
// Delays are searched on 0-200 ms and named only inside the physiological range (a delay outside
// it is listed with its verdict, not named): the electromechanical delay of human muscles, the time
// from EMG to force, is tens of milliseconds; Cavanagh & Komi 1979 (Eur J Appl Physiol 42:159-163)
// measured about 50 ms in the elbow flexors, and the values reported for limb muscles span about
// 10 to 100 ms (Norman & Komi 1979, Acta Physiol Scand 106:241-248; Corcos et al. 1992, J
// Electromyogr Kinesiol 2:59-68, show how much of the spread is the measuring apparatus). A
// longer apparent delay between envelope and moment stands for something else (activation and
// force build-up, another muscle's timing).
constexpr double kMaxDelaySearch = 0.2;  // s
constexpr double kMinEmd = 0.010, kMaxEmd = 0.100;  // s, the range a named delay must lie in
constexpr double kDelayStep = 0.005;
// Muscle twitch (emg_torque_model.h T_tau): Winter's critically damped EMG-to-force filter of about
// 3 Hz (tau = 1 / (2 pi 3 Hz) ~ 53 ms; Winter, Biomechanics and Motor Control of Human Movement, ch.
// on EMG and force; Olney & Winter 1985), which depends on the muscle: named within 20-100 ms
// (cut-off 8 down to 1.6 Hz), searched on 10-150 ms.
constexpr double kMinTwitch = 0.020, kMaxTwitch = 0.100, kMaxTwitchSearch = 0.150, kTwitchStep = 0.005;
constexpr double kMinA = -3.0;      // Lloyd & Besier 2003 (LB03 eq. 2): -3 < A < 0
constexpr double kAStep = 0.25;
// Moment arms: the alpha of a channel times (1 + c q) may change by at most this factor over the
// calibrated angle range, and keep its sign. Measured moment arms of the knee's extensors and
// flexors change by up to about a factor 2 over 0-90 deg of flexion (Herzog & Read 1993, J Anat
// 182:213-230); beyond 3 the term is no moment arm.
constexpr double kMaxMomentArmRatio = 3.0;
// Passive moment: Riener & Edrich 1999's population curves scaled by s_P within (0, kMaxPassiveScale]
// (model/passive_torque.h).

std::string Num(double v) { return NumberText(v, 4); }

enum class Kind { kCommonDelay, kTwitch, kTiming, kDelay, kAShape, kMomentArm, kPassive, kGmaxProxy, kRobust };

struct Cause {
  Kind kind;
  Muscle muscle = Muscle::kGMAX;  // delay
  int joint = -1;                 // moment arm, passive; -1: both joints
  std::string Label() const {
    switch (kind) {
      case Kind::kCommonDelay: return "electromechanical_delay(common)";
      case Kind::kTwitch: return "muscle_twitch(common)";
      case Kind::kTiming: return "electromechanical_delay(common) + muscle_twitch(common)";
      case Kind::kDelay: return std::string("electromechanical_delay(") + MuscleName(muscle) + ")";
      case Kind::kAShape: return "activation_nonlinearity";
      case Kind::kMomentArm: return std::string("moment_arm_angle(") + kJoint[joint] + ")";
      case Kind::kPassive: return std::string("passive_moment(") + kJoint[joint] + ")";
      case Kind::kGmaxProxy: return "missing_channel(GMAX via vasti, hip)";
      case Kind::kRobust: return "robust_fit(contact spikes)";
    }
    return "";
  }
  bool Acts(int j) const {
    if (kind == Kind::kMomentArm || kind == Kind::kPassive) return j == joint;
    if (kind == Kind::kGmaxProxy) return j == 0;
    if (kind == Kind::kDelay) return ActionSign(muscle, j) != 0 || (j == 0 && muscle == Muscle::kVM);
    return true;
  }
};

class Loop {
 public:
  Loop(const std::vector<const EmgRecording*>& recs, double train_fraction, int blocks) : recs_(recs) {
    opt_.train_fraction = train_fraction;
    opt_.blocks = blocks;
  }
  // Fixes the row weights and autocorrelation length from the linear form (comparable scores).
  EmgTorqueModel Baseline(const EmgModelSpec& s) {
    EmgTorqueModel m = FitEmgModel(s, recs_, opt_);
    opt_.autocorr_rows = m.autocorr_rows;
    opt_.weight[0] = m.weight[0], opt_.weight[1] = m.weight[1];
    return m;
  }
  EmgTorqueModel Fit(const EmgModelSpec& s) const { return FitEmgModel(s, recs_, opt_); }
  // The fit rows' weighted SSE of `s` (what the searches minimize).
  double Sse(const EmgModelSpec& s) const {
    EmgFitOptions o = opt_;
    o.fit_only = true;
    return FitEmgModel(s, recs_, o).sse_fit;
  }
  const EmgFitOptions& options() const { return opt_; }
  EmgFitOptions& options() { return opt_; }

  // Searched parameter: grid minimum of the fit rows' SSE (a grid of 2 steps, then the steps on
  // either side of its best), then its standard error from the profile's curvature: var = 2 s^2 /
  // SSE''(theta) (s^2: residual variance, autocorrelation included).
  double Search(EmgModelSpec* s, const std::function<double&(EmgModelSpec&)>& param, double lo, double hi,
                double step, double h, double* se) const {
    double best = param(*s), best_sse = 1e300;
    auto probe = [&](double v) {
      EmgModelSpec t = *s;
      param(t) = v;
      const double sse = Sse(t);
      if (sse < best_sse) best_sse = sse, best = v;
    };
    for (double v = lo; v <= hi + 1e-12; v += 2 * step) probe(v);
    const double coarse = best;
    for (double v : {coarse - step, coarse + step})
      if (v >= lo - 1e-12 && v <= hi + 1e-12) probe(v);
    param(*s) = best;
    *se = ProfileSe(*s, param, h);
    return best;
  }
  double ProfileSe(const EmgModelSpec& s, const std::function<double&(EmgModelSpec&)>& param, double h) const {
    EmgModelSpec a = s, b = s;
    param(a) -= h, param(b) += h;
    EmgFitOptions o = opt_;
    o.fit_only = true;
    const EmgTorqueModel m0 = FitEmgModel(s, recs_, o);
    const double c = (Sse(a) - 2 * m0.sse_fit + Sse(b)) / (h * h);
    const double s2 = m0.sse_fit / std::max(1.0, m0.n_fit - static_cast<double>(m0.terms.size())) * m0.autocorr_rows;
    return c > 0 ? std::sqrt(2 * s2 / c) : 1e300;
  }

 private:
  std::vector<const EmgRecording*> recs_;
  EmgFitOptions opt_;
};

std::function<double&(EmgModelSpec&)> DelayOf(Muscle m) {
  return [m](EmgModelSpec& s) -> double& { return s.delay_s[m]; };
}
double& AShapeOf(EmgModelSpec& s) { return s.a_shape; }
double& CommonDelayOf(EmgModelSpec& s) { return s.common_delay; }
double& TwitchOf(EmgModelSpec& s) { return s.twitch; }

// The spec with `c` added (searched parameters chosen on the fit rows). False if not applicable.
bool Apply(const Loop& loop, const Cause& c, EmgModelSpec* s) {
  switch (c.kind) {
    case Kind::kCommonDelay: {
      if (s->common_delay != 0) return false;
      loop.Search(s, CommonDelayOf, kDelayStep, kMaxDelaySearch, kDelayStep, kDelayStep, &s->common_delay_se);
      return true;
    }
    case Kind::kTwitch: {
      if (s->twitch != 0) return false;
      loop.Search(s, TwitchOf, kTwitchStep, kMaxTwitchSearch, kTwitchStep, kTwitchStep, &s->twitch_se);
      return true;
    }
    case Kind::kTiming: {  // both on the grid of their physiological ranges
      if (s->twitch != 0 || s->common_delay != 0) return false;
      double best = 1e300;
      EmgModelSpec b = *s;
      for (double tau = kMinTwitch; tau <= kMaxTwitch + 1e-9; tau += 4 * kTwitchStep)
        for (double dl = kMinEmd; dl <= kMaxEmd + 1e-9; dl += 4 * kDelayStep) {
          EmgModelSpec t = *s;
          t.twitch = tau, t.common_delay = dl;
          const double sse = loop.Sse(t);
          if (sse < best) best = sse, b = t;
        }
      *s = b;
      loop.Search(s, TwitchOf, kMinTwitch, kMaxTwitch, kTwitchStep, kTwitchStep, &s->twitch_se);
      loop.Search(s, CommonDelayOf, kMinEmd, kMaxEmd, kDelayStep, kDelayStep, &s->common_delay_se);
      return true;
    }
    case Kind::kDelay: {  // fewer parameters first: a muscle's own delay only after the common one
      if (s->common_delay == 0 || s->delay_s.count(c.muscle)) return false;
      double se;
      loop.Search(s, DelayOf(c.muscle), kDelayStep, kMaxDelaySearch, kDelayStep, kDelayStep, &se);
      s->delay_se[c.muscle] = se;
      return true;
    }
    case Kind::kAShape: {
      if (s->a_shape != 0) return false;
      double se;
      loop.Search(s, AShapeOf, kMinA, -kAStep, kAStep, 0.1, &se);
      s->a_shape_se = se;
      return true;
    }
    case Kind::kMomentArm:
      if (s->moment_arm[c.joint]) return false;
      s->moment_arm[c.joint] = true;
      return true;
    case Kind::kPassive:
      if (s->passive[c.joint]) return false;
      s->passive[c.joint] = true;
      return true;
    case Kind::kGmaxProxy:
      if (s->gmax_proxy) return false;
      s->gmax_proxy = true;
      return true;
    case Kind::kRobust:
      if (s->robust) return false;
      s->robust = true;
      return true;
  }
  return false;
}

// Significant and physiologically plausible? `why` says why not.
bool Admissible(const Cause& c, const EmgTorqueModel& m, std::string* why) {
  const EmgModelSpec& s = m.spec;
  auto t_of = [&](TermKind k, int joint, bool proxy_only) {
    double best = 0, sum = 0;
    for (const EmgTerm& t : m.terms)
      if (t.kind == k && t.joint == joint && (!proxy_only || t.proxy)) {
        best = std::max(best, t.se > 0 ? std::abs(t.value) / t.se : 0.0);
        sum += t.value;
      }
    return std::make_pair(best, sum);
  };
  auto delay_ok = [&](double d, double se) {
    if (!(d >= kMinEmd - 1e-9 && d <= kMaxEmd + 1e-9))
      return *why = "delay " + Num(d) + " s outside the electromechanical delay of human muscles (" + Num(kMinEmd) +
                    "-" + Num(kMaxEmd) + " s)",
             false;
    if (!(d > kMinT * se)) return *why = "delay " + Num(d) + " s, |t| " + Num(d / se) + " <= " + Num(kMinT), false;
    return true;
  };
  switch (c.kind) {
    case Kind::kCommonDelay: return delay_ok(s.common_delay, s.common_delay_se);
    case Kind::kTiming:
      if (!delay_ok(s.common_delay, s.common_delay_se)) return false;
      [[fallthrough]];
    case Kind::kTwitch:
      if (!(s.twitch >= kMinTwitch - 1e-9 && s.twitch <= kMaxTwitch + 1e-9))
        return *why = "twitch time constant " + Num(s.twitch) + " s outside " + Num(kMinTwitch) + "-" + Num(kMaxTwitch) + " s",
               false;
      if (!(s.twitch > kMinT * s.twitch_se))
        return *why = "twitch " + Num(s.twitch) + " s, |t| " + Num(s.twitch / s.twitch_se) + " <= " + Num(kMinT), false;
      return true;
    case Kind::kDelay: {
      const double d = s.Delay(c.muscle), se = s.delay_se.count(c.muscle) ? s.delay_se.at(c.muscle) : 1e300;
      if (!delay_ok(d, se)) return false;
      // The muscle's own delay must differ from the common one beyond its uncertainty.
      if (!(std::abs(d - s.common_delay) > kMinT * se))
        return *why = "delay " + Num(d) + " s within " + Num(kMinT) + " standard errors of the common " +
                      Num(s.common_delay) + " s",
               false;
      return true;
    }
    case Kind::kAShape:
      if (!(s.a_shape > kMinA && s.a_shape < 0)) return *why = "A " + Num(s.a_shape) + " at the end of (-3, 0)", false;
      if (!(std::abs(s.a_shape) > kMinT * s.a_shape_se))
        return *why = "A " + Num(s.a_shape) + ", |t| " + Num(std::abs(s.a_shape) / s.a_shape_se) + " <= " + Num(kMinT), false;
      return true;
    case Kind::kMomentArm: {
      const auto t = t_of(TermKind::kAlphaQ, c.joint, false);
      if (!(t.first > kMinT)) return *why = "no alpha_q with |t| > " + Num(kMinT), false;
      // Every channel whose moment arm changes significantly: alpha + alpha_q q over the calibrated
      // angles keeps its sign and changes by at most kMaxMomentArmRatio.
      const int j = c.joint;
      for (const EmgTerm& q : m.terms) {
        if (q.kind != TermKind::kAlphaQ || q.joint != j || !(std::abs(q.value) > 2 * q.se)) continue;
        for (const EmgTerm& a : m.terms) {
          if (a.kind != TermKind::kAlpha || a.joint != j || a.channel != q.channel || a.proxy != q.proxy) continue;
          const double lo = a.value + q.value * m.range.q_lo[j], hi = a.value + q.value * m.range.q_hi[j];
          const double r = std::max(std::abs(lo), std::abs(hi)) / std::max(1e-12, std::min(std::abs(lo), std::abs(hi)));
          if (lo * hi <= 0 || r > kMaxMomentArmRatio)
            return *why = a.Name() + " goes from " + Num(lo) + " to " + Num(hi) + " N m over the calibrated angles (a moment "
                          "arm keeps its sign and changes by at most a factor " + Num(kMaxMomentArmRatio) + ")",
                   false;
        }
      }
      return true;
    }
    case Kind::kPassive: {
      const auto t = t_of(TermKind::kPassive, c.joint, false);
      if (!(t.second > 0 && t.second <= kMaxPassiveScale))
        return *why = "passive scale " + Num(t.second) + " outside (0, " + Num(kMaxPassiveScale) + "]", false;
      if (!(t.first > kMinT)) return *why = "passive scale |t| " + Num(t.first) + " <= " + Num(kMinT), false;
      return true;
    }
    case Kind::kGmaxProxy: {
      const auto t = t_of(TermKind::kAlpha, 0, true);
      if (!(t.second < 0)) return *why = "the vasti pull the hip into flexion (GMAX extends it)", false;
      if (!(t.first > kMinT)) return *why = "no vasti alpha at the hip with |t| > " + Num(kMinT), false;
      return true;
    }
    case Kind::kRobust: return true;
  }
  return true;
}

// Refines the searched parameters of `s` jointly on the fit rows: coordinate descent over the
// delays and A, each a grid minimum given the others, repeated until a whole pass moves none
// (the SSE never rises, and the grid is finite, so it ends; kMaxRefinePasses bounds the cost).
constexpr int kMaxRefinePasses = 10;
void Refine(const Loop& loop, EmgModelSpec* s) {
  for (int pass = 0; pass < kMaxRefinePasses; ++pass) {
    bool moved = false;
    if (s->common_delay != 0) {
      const double before = s->common_delay;
      loop.Search(s, CommonDelayOf, kMinEmd, kMaxEmd, kDelayStep, kDelayStep, &s->common_delay_se);
      moved |= s->common_delay != before;
    }
    if (s->twitch != 0) {
      const double before = s->twitch;
      loop.Search(s, TwitchOf, kMinTwitch, kMaxTwitch, kTwitchStep, kTwitchStep, &s->twitch_se);
      moved |= s->twitch != before;
    }
    for (auto& d : s->delay_s) {
      const double before = d.second;
      double se;
      loop.Search(s, DelayOf(d.first), kMinEmd, kMaxEmd, kDelayStep, kDelayStep, &se);
      s->delay_se[d.first] = se;
      moved |= s->delay_s[d.first] != before;
    }
    if (s->a_shape != 0) {
      const double before = s->a_shape;
      loop.Search(s, AShapeOf, kMinA, -kAStep, kAStep, 0.1, &s->a_shape_se);
      moved |= s->a_shape != before;
    }
    if (!moved) break;
  }
}

void ProfileAll(const Loop& loop, EmgModelSpec* s) {
  if (s->common_delay != 0) s->common_delay_se = loop.ProfileSe(*s, CommonDelayOf, kDelayStep);
  if (s->twitch != 0) s->twitch_se = loop.ProfileSe(*s, TwitchOf, kTwitchStep);
  for (auto& d : s->delay_s) s->delay_se[d.first] = loop.ProfileSe(*s, DelayOf(d.first), kDelayStep);
  if (s->a_shape != 0) s->a_shape_se = loop.ProfileSe(*s, AShapeOf, 0.1);
}

std::string Scores(const EmgTorqueModel& m) {
  std::string o;
  for (int j = 0; j < 2; ++j)
    o += std::string(j ? "; " : "") + kJoint[j] + " cross-validated R^2 " + Num(m.figures[j].r2_cv) + ", last 30 % R^2 " +
         Num(m.figures[j].r2_heldout_trim) + ", rms " + Num(m.figures[j].rms_heldout_trim) + " N m";
  return o;
}


// Muscles with several channels (the vasti, the two hamstrings) whose channels' alphas in `m` are
// not separable: one of them held at zero by the signed fit or, fitted free of sign, against its
// muscle's action (HJ15 eq. 23-24 signs) beyond two standard errors. `why` per muscle.
std::map<Muscle, std::string> WrongSignMuscles(const EmgTorqueModel& m, const EmgRecording& r) {
  std::map<Muscle, std::string> out;
  for (const EmgTerm& t : m.terms) {
    if (t.kind != TermKind::kAlpha || t.proxy || t.channel.find('+') != std::string::npos) continue;
    if (std::count(r.muscle.begin(), r.muscle.end(), t.muscle) < 2) continue;
    std::string& o = out[t.muscle];
    if (t.held)
      o += std::string(o.empty() ? "" : "; ") + t.Name() + " held at zero at the " + kJoint[t.joint];
    else if (t.value * t.ExpectedSign() < 0 && std::abs(t.value) > 2 * t.se)
      o += std::string(o.empty() ? "" : "; ") + t.Name() + " " + Num(t.value) + " +- " + Num(t.se) + " N m at the " +
           kJoint[t.joint] + ", against the muscle's action";
    if (o.empty()) out.erase(t.muscle);
  }
  return out;
}

// Envelope correlation of the first two channels of muscle `mu`.
double ChannelCorrelation(const EmgRecording& r, Muscle mu) {
  std::vector<size_t> ch;
  for (size_t c = 0; c < r.channels.size(); ++c)
    if (r.muscle[c] == mu) ch.push_back(c);
  const std::vector<double>& x = r.e[ch[0]];
  const std::vector<double>& y = r.e[ch[1]];
  double mx = 0, my = 0, sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size()), my /= static_cast<double>(y.size());
  for (size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
  return sxy / std::sqrt(sxx * syy);
}

}  // namespace

EmgBandCeiling BandCeiling(const EmgTorqueModel& model, const std::vector<const EmgRecording*>& recs, int joint) {
  struct Series {
    double fs;
    std::vector<double> pred, meas;
    std::vector<size_t> scored;
  };
  std::vector<Series> ser;
  for (const EmgRecording* r : recs) {
    const size_t n = r->size();
    if (n < 50 || !r->has_moments() || !(r->t.back() > r->t.front()))
      throw InputError(r->source + ": the band ceiling needs a recording with moments of at least 50 samples");
    Series s{static_cast<double>(n - 1) / (r->t.back() - r->t.front()), PredictMoment(model, *r, joint), r->tau[joint],
             WithinSpikeLimit(r->tau[joint], 0, n)};
    // Spikes bridged linearly between their scored neighbours (they are not scored; their ringing
    // through the filter would be).
    std::vector<char> in(n, 0);
    for (size_t i : s.scored) in[i] = 1;
    for (size_t i = 0; i < n; ++i) {
      if (in[i]) continue;
      size_t a = i, b = i;
      while (a > 0 && !in[a]) --a;
      while (b + 1 < n && !in[b]) ++b;
      const double ya = in[a] ? s.meas[a] : s.meas[b], yb = in[b] ? s.meas[b] : ya;
      const double f = b > a ? static_cast<double>(i - a) / static_cast<double>(b - a) : 0.0;
      s.meas[i] = ya + f * (yb - ya);
    }
    ser.push_back(std::move(s));
  }
  // Energy above f of the estimate (on every sample, or on the scored ones) and of the measured
  // moment (scored), and the measured sum of squares about its mean, pooled.
  struct Energy {
    double pred_all = 0, var_pred = 0, pred = 0, meas = 0, sst = 0;
  };
  auto energy = [&](double f, bool measured) {
    Energy e;
    for (const Series& s : ser) {
      const auto hp = dsp::DesignButterworth(4, dsp::BandType::kHighPass, s.fs, f);
      const std::vector<double> hpred = dsp::FiltFilt(hp, s.pred);
      double mp = 0;
      for (double v : s.pred) mp += v / static_cast<double>(s.pred.size());
      for (size_t i = 0; i < s.pred.size(); ++i) e.pred_all += hpred[i] * hpred[i], e.var_pred += (s.pred[i] - mp) * (s.pred[i] - mp);
      if (!measured) continue;
      const std::vector<double> hmeas = dsp::FiltFilt(hp, s.meas);
      double mm = 0;
      for (size_t i : s.scored) mm += s.meas[i] / static_cast<double>(s.scored.size());
      for (size_t i : s.scored)
        e.pred += hpred[i] * hpred[i], e.meas += hmeas[i] * hmeas[i], e.sst += (s.meas[i] - mm) * (s.meas[i] - mm);
    }
    return e;
  };
  double nyquist = 1e300;
  for (const Series& s : ser) nyquist = std::min(nyquist, s.fs / 2);
  EmgBandCeiling c;
  c.band_hz = 0.5;
  for (;; c.band_hz += 0.5) {
    const Energy e = energy(c.band_hz, false);
    if (!(e.pred_all > kBandResidue * e.var_pred) || c.band_hz + 0.5 >= 0.9 * nyquist) break;
  }
  const Energy e = energy(c.band_hz, true);
  if (!(e.sst > 0)) return c;
  c.share_above = e.meas / e.sst, c.estimate_share = e.pred / e.sst;
  const double d = std::sqrt(c.share_above) - std::sqrt(c.estimate_share);
  c.r2 = d > 0 ? 1 - d * d : 1.0;
  return c;
}

EmgDiagnosis DiagnoseEmg(const std::vector<const EmgRecording*>& recs, const EmgDiagnoseOptions& opt) {
  if (recs.empty()) throw InputError("emg-fit: no recording");
  if (recs.size() < 2 && opt.blocks < 2)
    throw InputError("emg-fit: --blocks " + std::to_string(opt.blocks) + ": expected at least 2 cross-validation blocks");
  EmgDiagnosis d;
  d.holdout_fraction = opt.holdout_fraction;
  d.folds_are_recordings = recs.size() >= 2;
  d.folds = d.folds_are_recordings ? static_cast<int>(recs.size()) : opt.blocks;
  d.missing = recs[0]->missing;
  for (const EmgRecording* r : recs) {
    d.sources.push_back(r->source);
    for (const std::string& n : r->notes) d.notes.push_back(r->source + ": " + n);
  }
  Loop loop(recs, 1 - opt.holdout_fraction, opt.blocks);
  EmgModelSpec spec;
  EmgTorqueModel cur = loop.Baseline(spec);
  d.steps.push_back({"linear form (HJ15 eq. 26)", "the papers' model", cur});
  d.selection.push_back("start: " + d.steps[0].added + ": " + Scores(cur));
  const bool recs_out = d.folds_are_recordings;
  const std::string fold_word = recs_out ? "recording" : "block";
  auto gain = [](double now, double before) { return before > 0 ? 100 * (1 - now / before) : 0.0; };
  // The validation gates of a candidate model `m` against the current one: cross-validated error
  // (each fold left out in turn) drops by kMinHeldoutGain at a joint the cause acts on and in sum;
  // with several recordings every recording left out in turn gains (sum over joints).
  auto validate = [&](const EmgTorqueModel& m, const std::function<bool(int)>& acts, EmgCandidateScore* sc) {
    bool enough = false;
    double before = 0, after = 0;
    for (int j = 0; j < 2; ++j) {
      sc->gain_pct[j] = gain(m.sse_heldout[j], cur.sse_heldout[j]);
      sc->cv_gain_pct[j] = gain(m.sse_cv[j], cur.sse_cv[j]);
      enough |= acts(j) && sc->cv_gain_pct[j] >= 100 * kMinHeldoutGain;
      before += cur.sse_cv[j], after += m.sse_cv[j];
    }
    if (!enough || !(after < before)) {
      sc->verdict = "cross-validated gain below " + Num(100 * kMinHeldoutGain) + " % where it acts";
      return false;
    }
    if (recs_out)
      for (size_t k = 0; k < m.sse_fold.size(); ++k)
        if (!(m.sse_fold[k][0] + m.sse_fold[k][1] < cur.sse_fold[k][0] + cur.sse_fold[k][1])) {
          sc->verdict = "no gain on recording " + std::to_string(k + 1) + " left out (" + recs[k]->source + ")";
          return false;
        }
    return true;
  };
  auto gains_text = [&](const EmgCandidateScore& sc) {
    return "cross-validated gain (" + fold_word + "s left out) hip " + Num(sc.cv_gain_pct[0]) + " %, knee " +
           Num(sc.cv_gain_pct[1]) + " %; last 30 % hip " + Num(sc.gain_pct[0]) + " %, knee " + Num(sc.gain_pct[1]) + " %";
  };
  // Physiology first: every alpha with its muscle's sign (a muscle only pulls), whatever it costs
  // the linear form; freeing the signs is judged at the end like a cause.
  if (opt.signed_alphas) {
    spec.signed_alphas = true;
    const EmgTorqueModel m = loop.Fit(spec);
    std::string list;
    for (const EmgTerm& t : m.terms)
      if (t.held) list += (list.empty() ? "" : ", ") + t.Name() + " at the " + kJoint[t.joint];
    auto change = [&](int j) {
      const double g = -gain(m.sse_cv[j], cur.sse_cv[j]), v = g == 0 ? 0.0 : g;  // no "-0"
      return (v > 0 ? "+" : "") + Num(v) + " %";
    };
    const std::string why = "alphas with their muscles' signs (sign-constrained least squares); held at zero: " +
                            (list.empty() ? std::string("none") : list) + "; cross-validated error hip " + change(0) +
                            ", knee " + change(1);
    cur = m;
    if (!list.empty()) d.steps.push_back({"alphas signed (muscles pull)", why, cur});  // else the same model
    d.selection.push_back(why + ": " + Scores(cur));
  }
  std::vector<Cause> causes = {{Kind::kCommonDelay}, {Kind::kTwitch}, {Kind::kTiming}};
  for (int m = 0; m < kNumMuscles; ++m)
    if (std::find(recs[0]->muscle.begin(), recs[0]->muscle.end(), MuscleAt(m)) != recs[0]->muscle.end())
      causes.push_back({Kind::kDelay, MuscleAt(m)});
  causes.push_back({Kind::kAShape});
  for (int j = 0; j < 2; ++j) causes.push_back({Kind::kMomentArm, Muscle::kGMAX, j});
  for (int j = 0; j < 2; ++j) causes.push_back({Kind::kPassive, Muscle::kGMAX, j});
  const bool gmax_missing = std::find(d.missing.begin(), d.missing.end(), "GMAX") != d.missing.end();
  if (gmax_missing && std::find(recs[0]->muscle.begin(), recs[0]->muscle.end(), Muscle::kVM) != recs[0]->muscle.end())
    causes.push_back({Kind::kGmaxProxy});

  // Robust handling first: it changes the rows every other cause is fitted on (no BIC comparison).
  if (opt.robust_candidate) {
    EmgModelSpec s = spec;
    s.robust = true;
    const EmgTorqueModel m = loop.Fit(s);
    EmgCandidateScore sc;
    sc.label = Cause{Kind::kRobust}.Label();
    sc.added = validate(m, [](int) { return true; }, &sc);
    if (sc.added) sc.verdict = "added: cross-validated error drops";
    d.scores.push_back(sc);
    if (sc.added) {
      spec = s, cur = m;
      d.steps.push_back({sc.label, "fit rows beyond " + Num(kSpikeMads) + " scaled MADs of the median moment left out; " +
                                       gains_text(sc), cur});
      d.selection.push_back("add " + sc.label + ": " + Scores(cur));
    } else {
      d.selection.push_back("robust fit not added: " + sc.verdict + " (" + gains_text(sc) + ")");
    }
  }

  for (int round = 1; round <= opt.max_steps; ++round) {
    struct Option {
      Cause c;
      EmgModelSpec s;
      EmgTorqueModel m;
      size_t score;
    };
    std::vector<Option> ok;
    for (const Cause& c : causes) {
      EmgModelSpec s = spec;
      if (!Apply(loop, c, &s)) continue;
      const EmgTorqueModel m = loop.Fit(s);
      EmgCandidateScore sc;
      sc.round = round;
      sc.label = c.Label();
      if (c.kind == Kind::kCommonDelay) sc.label += " " + Num(s.common_delay) + " s";
      if (c.kind == Kind::kTwitch || c.kind == Kind::kTiming) sc.label += " tau " + Num(s.twitch) + " s";
      if (c.kind == Kind::kTiming) sc.label += ", delay " + Num(s.common_delay) + " s";
      if (c.kind == Kind::kDelay) sc.label += " " + Num(s.Delay(c.muscle)) + " s";
      if (c.kind == Kind::kAShape) sc.label += " A = " + Num(s.a_shape);
      sc.delta_bic = m.bic - cur.bic;
      std::string why;
      if (!(sc.delta_bic < -kBicMargin)) {
        sc.verdict = "BIC drop " + Num(-sc.delta_bic) + " <= " + Num(kBicMargin);
        for (int j = 0; j < 2; ++j)
          sc.gain_pct[j] = gain(m.sse_heldout[j], cur.sse_heldout[j]), sc.cv_gain_pct[j] = gain(m.sse_cv[j], cur.sse_cv[j]);
      } else if (!validate(m, [&c](int j) { return c.Acts(j); }, &sc)) {
      } else if (!Admissible(c, m, &why)) {
        sc.verdict = "outside its range or not significant: " + why;
      } else {
        sc.verdict = "admissible";
      }
      d.scores.push_back(sc);
      if (sc.verdict == "admissible") ok.push_back({c, s, m, d.scores.size() - 1});
    }
    if (ok.empty()) {
      d.selection.push_back("stop: no remaining cause passes the gates");
      break;
    }
    const Option* best = &*std::min_element(ok.begin(), ok.end(), [](const Option& a, const Option& b) { return a.m.bic < b.m.bic; });
    EmgCandidateScore& sc = d.scores[best->score];
    sc.added = true;
    sc.verdict = "added (lowest BIC of the admissible)";
    spec = best->s;
    Refine(loop, &spec);
    cur = loop.Fit(spec);
    const std::string why = "BIC " + Num(sc.delta_bic) + ", " + gains_text(sc);
    d.steps.push_back({sc.label, why, cur});
    d.selection.push_back("add " + sc.label + " (" + why + "): " + Scores(cur));
  }
  // Signs: the loop's fits keep every alpha's sign (EmgModelSpec::signed_alphas). Freeing them is
  // a cause like the others: the alphas against their muscles' action must pay where they act on
  // the data left out (the gates above: BIC, cross-validated gain at a joint with a held alpha, every
  // recording left out gaining); else the alphas held at zero are reported as not separable there.
  if (spec.signed_alphas) {
    std::vector<std::string> held;
    for (const EmgTerm& t : cur.terms)
      if (t.held) held.push_back(t.Name() + " at the " + kJoint[t.joint]);
    if (!held.empty()) {
      EmgModelSpec s = spec;
      s.signed_alphas = false;
      const EmgTorqueModel m = loop.Fit(s);
      EmgCandidateScore sc;
      sc.round = static_cast<int>(d.steps.size());
      sc.label = "alphas_free_of_sign";
      sc.delta_bic = m.bic - cur.bic;
      auto acts = [&](int j) {
        for (const EmgTerm& t : cur.terms)
          if (t.held && t.joint == j) return true;
        return false;
      };
      if (!(sc.delta_bic < -kBicMargin)) {
        sc.verdict = "BIC drop " + Num(-sc.delta_bic) + " <= " + Num(kBicMargin);
        for (int j = 0; j < 2; ++j)
          sc.gain_pct[j] = gain(m.sse_heldout[j], cur.sse_heldout[j]), sc.cv_gain_pct[j] = gain(m.sse_cv[j], cur.sse_cv[j]);
      } else if (validate(m, acts, &sc)) {
        double t_max = 0;  // the freed alphas: significant against their muscles' action
        for (const EmgTerm& h : cur.terms)
          for (const EmgTerm& f : m.terms)
            if (h.held && f.kind == h.kind && f.joint == h.joint && f.channel == h.channel && f.proxy == h.proxy &&
                f.se > 0)
              t_max = std::max(t_max, std::abs(f.value) / f.se);
        if (t_max > kMinT) sc.added = true, sc.verdict = "added: the signs pay on the data left out";
        else sc.verdict = "no freed alpha with |t| > " + Num(kMinT) + " (largest " + Num(t_max) + ")";
      }
      d.scores.push_back(sc);
      std::string list;
      for (const std::string& h : held) list += (list.empty() ? "" : ", ") + h;
      if (sc.added) {
        spec = s, cur = m;
        d.steps.push_back({sc.label, list + " against their muscles' action; " + gains_text(sc), cur});
        d.selection.push_back("free the alphas' signs (" + list + "; " + gains_text(sc) + "): " + Scores(cur));
      } else {
        d.selection.push_back("signs kept: " + list + " held at zero; freeing them: " + sc.verdict + " (" +
                              gains_text(sc) + ")");
      }
    }
  }
  // Collinear channels of one muscle (the vasti, the two hamstrings): when the chosen structure
  // fitted on every sample holds one of them at zero or (free of sign) gives it an alpha against
  // the muscle's action, the channels are
  // pooled (one alpha of their mean envelope) if the pooled alphas keep their expected signs and
  // the cross-validated error rises by at most kParsimony; otherwise they are reported as not
  // separable.
  {
    Loop all(recs, 1.0, opt.blocks);
    const EmgTorqueModel full = all.Fit(spec);
    for (const auto& w : WrongSignMuscles(full, *recs[0])) {
      EmgModelSpec s = spec;
      s.pooled.push_back(w.first);
      const EmgTorqueModel pooled = all.Fit(s);
      bool signs = true;
      for (const EmgTerm& t : pooled.terms)
        if (t.kind == TermKind::kAlpha && t.muscle == w.first && !t.proxy &&
            (t.held || (t.value * t.ExpectedSign() < 0 && std::abs(t.value) > 2 * t.se)))
          signs = false;
      const double before = full.sse_cv[0] + full.sse_cv[1], after = pooled.sse_cv[0] + pooled.sse_cv[1];
      const std::string what = std::string(MuscleName(w.first)) + "'s channels (" + w.second + "; " +
                               "envelope correlation " + Num(ChannelCorrelation(*recs[0], w.first)) + ")";
      if (signs && after <= (1 + kParsimony) * before) {
        spec = s;
        cur = loop.Fit(spec);
        d.steps.push_back({"pooled " + std::string(MuscleName(w.first)) + " channels", what, cur});
        d.selection.push_back("pool " + what + ": " + Scores(cur));
        d.notes.push_back(what + ": pooled, one alpha of their mean envelope");
      } else {
        d.notes.push_back(what + ": not separable (pooled, " +
                          (signs ? "the cross-validated error rises by " + Num(100 * (after / before - 1)) + " %"
                                 : std::string("their alpha is still against the action")) +
                          (spec.signed_alphas ? "); kept apart, one held at zero at its joint"
                                              : "); kept apart, their alphas are not physiological"));
      }
    }
  }
  // The calibration: the chosen structure fitted on every sample.
  {
    Loop all(recs, 1.0, opt.blocks);
    EmgFitOptions& o = all.options();
    o.autocorr_rows = 0;
    ProfileAll(all, &spec);
    d.calibration = all.Fit(spec);
    // The papers' form on the same samples: what predicts a joint of another gait (kOtherGaitShare).
    d.calibration.papers_terms = all.Fit(EmgModelSpec{}).terms;
    // Outside the calibrated angles the angle-dependent terms continue as emg_torque_model.h says.
    d.calibration.spec.bounded = true;
    for (int j = 0; j < 2; ++j)
      d.calibration.spec.q_lo[j] = d.calibration.range.q_lo[j], d.calibration.spec.q_hi[j] = d.calibration.range.q_hi[j];
  }
  // The musculoskeletal form (issue 42), with the twitch the loop named (none: none), cross-validated on
  // the same folds; chosen at a joint where it gains the loop's kMinHeldoutGain on the linear
  // calibration's cross-validated error (the same samples scored).
  if (opt.musculoskeletal) {
    EmgMskFitOptions mo;
    mo.blocks = opt.blocks;
    mo.strength_bounds = opt.strength_bounds;
    d.calibration.msk = FitEmgMsk(recs, d.calibration.spec.twitch, mo);
    const EmgMskModel& m = d.calibration.msk;
    for (int j = 0; j < 2; ++j) {
      const double lin = 1 - d.calibration.figures[j].r2_cv, msk = 1 - m.r2_cv[j];
      d.calibration.msk_form[j] = msk <= (1 - kMinHeldoutGain) * lin;
      const double gain = lin > 0 ? 100 * (1 - msk / lin) : 0;
      d.selection.push_back(std::string(kJoint[j]) + ": musculoskeletal form cross-validated R^2 " + Num(m.r2_cv[j]) +
                            " against the linear calibration's " + Num(d.calibration.figures[j].r2_cv) + " (gain " +
                            Num(gain) + " %, " + Num(100 * kMinHeldoutGain) + " % needed): " +
                            (d.calibration.msk_form[j] ? "musculoskeletal form" : "linear form"));
      d.notes.push_back(std::string(kJoint[j]) + ": the recorded muscles can reach " + Num(100 * m.reachable_share[j]) +
                        " % of the calibration moment at full activation and their largest strength, " +
                        Num(100 * m.reachable_share_recorded[j]) +
                        " % at their recorded activation (the rest belongs to muscles nobody recorded, or to "
                        "passive tissues)");
    }
  }
  // Channels whose fitted alpha contradicts their muscle's action (HJ15 eq. 23-24 signs): crosstalk,
  // a channel standing for a missing muscle, or collinearity. Fitted free of sign, reported; held at
  // zero by the signed fit, reported with the value the same structure gives it free of sign.
  EmgTorqueModel free_signs;
  for (const EmgTerm& t : d.calibration.terms) {
    if (t.kind != TermKind::kAlpha) continue;
    const std::string why = "crosstalk, a missing muscle's activity, or collinearity";
    if (t.held) {
      if (free_signs.terms.empty()) {
        Loop all(recs, 1.0, opt.blocks);
        EmgModelSpec s = spec;
        s.signed_alphas = false;
        free_signs = all.Fit(s);
      }
      for (const EmgTerm& f : free_signs.terms)
        if (f.kind == TermKind::kAlpha && f.joint == t.joint && f.channel == t.channel && f.proxy == t.proxy)
          d.notes.push_back(t.Name() + " at the " + kJoint[t.joint] + ": held at zero (" + MuscleName(t.muscle) +
                            "'s sign there); free of sign it is " + Num(f.value) + " +- " + Num(f.se) + " N m (" + why +
                            "): not separable at this joint");
    } else if (t.value * t.ExpectedSign() < 0 && std::abs(t.value) > 2 * t.se) {
      d.notes.push_back(t.Name() + " at the " + kJoint[t.joint] + ": " + Num(t.value) + " +- " + Num(t.se) +
                        " N m, against the " + MuscleName(t.muscle) + "'s action there (" + why + ")");
    }
  }
  // Plot series of the first recording.
  const EmgRecording& r = *recs[0];
  if (d.calibration.msk.present) d.first_recording = r;
  d.t = r.t;
  d.split = static_cast<size_t>(std::floor((1 - opt.holdout_fraction) * static_cast<double>(r.size())));
  for (int j = 0; j < 2; ++j) {
    d.measured[j] = r.tau[j];
    d.linear[j] = PredictMoment(d.steps.front().model, r, j);
    d.final_[j] = PredictMoment(d.steps.back().model, r, j);
    d.ceiling[j] = BandCeiling(d.calibration, recs, j);
  }
  return d;
}

}  // namespace exotwin
