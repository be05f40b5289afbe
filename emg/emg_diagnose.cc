#include "emg/emg_diagnose.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "diagnosis/diagnose_select.h"
#include "formats/number_text.h"
#include "core/error.h"

namespace exotwin {
namespace {

const char* kJoint[2] = {"hip", "knee"};
constexpr double kMaxDelay = 0.2;   // s: EMG-to-force delay, activation dynamics included
constexpr double kDelayStep = 0.005;
constexpr double kMinA = -3.0;      // Lloyd & Besier 2003: -3 < A < 0
constexpr double kAStep = 0.25;

std::string Num(double v) { return NumberText(v, 4); }

enum class Kind { kDelay, kAShape, kMomentArm, kPassive, kGmaxProxy, kRobust };

struct Cause {
  Kind kind;
  Muscle muscle = Muscle::kGMAX;  // delay
  int joint = -1;                 // moment arm, passive; -1: both joints
  std::string Label() const {
    switch (kind) {
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
  Loop(const std::vector<const EmgRecording*>& recs, double train_fraction) : recs_(recs) {
    opt_.train_fraction = train_fraction;
  }
  // Fixes the row weights and autocorrelation length from the linear form (comparable scores).
  EmgTorqueModel Baseline(const EmgModelSpec& s) {
    EmgTorqueModel m = FitEmgModel(s, recs_, opt_);
    opt_.autocorr_rows = m.autocorr_rows;
    opt_.weight[0] = m.weight[0], opt_.weight[1] = m.weight[1];
    return m;
  }
  EmgTorqueModel Fit(const EmgModelSpec& s) const { return FitEmgModel(s, recs_, opt_); }
  const EmgFitOptions& options() const { return opt_; }
  EmgFitOptions& options() { return opt_; }

  // Searched parameter: grid minimum of the fit rows' SSE, then its standard error from the
  // profile's curvature: var = 2 s^2 / SSE''(theta) (s^2: residual variance, autocorrelation
  // included).
  double Search(EmgModelSpec* s, const std::function<double&(EmgModelSpec&)>& param, double lo, double hi,
                double step, double h, double* se) const {
    double best = param(*s), best_sse = 1e300;
    for (double v = lo; v <= hi + 1e-12; v += step) {
      EmgModelSpec t = *s;
      param(t) = v;
      const double sse = Fit(t).sse_fit;
      if (sse < best_sse) best_sse = sse, best = v;
    }
    param(*s) = best;
    *se = ProfileSe(*s, param, h);
    return best;
  }
  double ProfileSe(const EmgModelSpec& s, const std::function<double&(EmgModelSpec&)>& param, double h) const {
    EmgModelSpec a = s, b = s;
    param(a) -= h, param(b) += h;
    const EmgTorqueModel m0 = Fit(s);
    const double c = (Fit(a).sse_fit - 2 * m0.sse_fit + Fit(b).sse_fit) / (h * h);
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

// The spec with `c` added (searched parameters chosen on the fit rows). False if not applicable.
bool Apply(const Loop& loop, const Cause& c, EmgModelSpec* s) {
  switch (c.kind) {
    case Kind::kDelay: {
      if (s->delay_s.count(c.muscle)) return false;
      double se;
      loop.Search(s, DelayOf(c.muscle), kDelayStep, kMaxDelay, kDelayStep, kDelayStep, &se);
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
  switch (c.kind) {
    case Kind::kDelay: {
      const double d = s.Delay(c.muscle), se = s.delay_se.count(c.muscle) ? s.delay_se.at(c.muscle) : 1e300;
      if (!(d > 0 && d < kMaxDelay)) return *why = "delay " + Num(d) + " s at the end of (0, " + Num(kMaxDelay) + ") s", false;
      if (!(d > kMinT * se)) return *why = "delay " + Num(d) + " s, |t| " + Num(d / se) + " <= " + Num(kMinT), false;
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
      return true;
    }
    case Kind::kPassive: {
      const auto t = t_of(TermKind::kPassive, c.joint, false);
      if (!(t.second > 0)) return *why = "negative passive scale " + Num(t.second), false;
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
    for (auto& d : s->delay_s) {
      const double before = d.second;
      double se;
      loop.Search(s, DelayOf(d.first), kDelayStep, kMaxDelay, kDelayStep, kDelayStep, &se);
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
  for (auto& d : s->delay_s) s->delay_se[d.first] = loop.ProfileSe(*s, DelayOf(d.first), kDelayStep);
  if (s->a_shape != 0) s->a_shape_se = loop.ProfileSe(*s, AShapeOf, 0.1);
}

std::string Scores(const EmgTorqueModel& m) {
  std::string o;
  for (int j = 0; j < 2; ++j)
    o += std::string(j ? "; " : "") + kJoint[j] + " held-out R^2 " + Num(m.figures[j].r2_heldout_trim) + ", rms " +
         Num(m.figures[j].rms_heldout_trim) + " N m";
  return o;
}

}  // namespace

EmgDiagnosis DiagnoseEmg(const std::vector<const EmgRecording*>& recs, const EmgDiagnoseOptions& opt) {
  if (recs.empty()) throw InputError("emg-fit: no recording");
  EmgDiagnosis d;
  d.holdout_fraction = opt.holdout_fraction;
  d.leave_one_out = recs.size() >= 2;
  d.missing = recs[0]->missing;
  for (const EmgRecording* r : recs) {
    d.sources.push_back(r->source);
    for (const std::string& n : r->notes) d.notes.push_back(r->source + ": " + n);
  }
  Loop loop(recs, 1 - opt.holdout_fraction);
  EmgModelSpec spec;
  EmgTorqueModel cur = loop.Baseline(spec);
  d.steps.push_back({"linear form (HJ15 eq. 26)", "the papers' model", cur});
  d.selection.push_back("start: linear form (HJ15 eq. 26): " + Scores(cur));
  const bool loo = d.leave_one_out;
  auto gain = [](double now, double before) { return before > 0 ? 100 * (1 - now / before) : 0.0; };
  std::vector<Cause> causes;
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
    double total_before = 0, total_after = 0;
    bool enough = false;
    for (int j = 0; j < 2; ++j) {
      sc.gain_pct[j] = gain(m.sse_heldout[j], cur.sse_heldout[j]);
      total_before += cur.sse_heldout[j], total_after += m.sse_heldout[j];
      enough |= sc.gain_pct[j] >= 100 * kMinHeldoutGain;
      if (loo) sc.left_out_gain_pct[j] = gain(m.sse_left_out[j], cur.sse_left_out[j]);
    }
    const bool loo_ok = !loo || m.sse_left_out[0] + m.sse_left_out[1] < cur.sse_left_out[0] + cur.sse_left_out[1];
    sc.added = enough && total_after < total_before && loo_ok;
    sc.verdict = sc.added ? "added: held-out error drops" : "not added: held-out gain below " + Num(100 * kMinHeldoutGain) + " %";
    d.scores.push_back(sc);
    if (sc.added) {
      spec = s, cur = m;
      d.steps.push_back({sc.label, "fit rows beyond " + Num(kSpikeMads) + " scaled MADs of the median moment left out; held-out gain hip " +
                                       Num(sc.gain_pct[0]) + " %, knee " + Num(sc.gain_pct[1]) + " %", cur});
      d.selection.push_back("add " + sc.label + ": " + Scores(cur));
    } else {
      d.selection.push_back("robust fit not added: held-out gain hip " + Num(sc.gain_pct[0]) + " %, knee " +
                            Num(sc.gain_pct[1]) + " % (needed " + Num(100 * kMinHeldoutGain) + " % at one joint)");
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
      if (c.kind == Kind::kDelay) sc.label += " " + Num(s.Delay(c.muscle)) + " s";
      if (c.kind == Kind::kAShape) sc.label += " A = " + Num(s.a_shape);
      sc.delta_bic = m.bic - cur.bic;
      bool enough = false;
      double total_before = 0, total_after = 0, loo_before = 0, loo_after = 0;
      bool loo_enough = !loo;
      for (int j = 0; j < 2; ++j) {
        sc.gain_pct[j] = gain(m.sse_heldout[j], cur.sse_heldout[j]);
        if (loo) sc.left_out_gain_pct[j] = gain(m.sse_left_out[j], cur.sse_left_out[j]);
        if (c.Acts(j) && sc.gain_pct[j] >= 100 * kMinHeldoutGain) {
          enough = true;
          if (loo && sc.left_out_gain_pct[j] >= 100 * kMinHeldoutGain) loo_enough = true;
        }
        total_before += cur.sse_heldout[j], total_after += m.sse_heldout[j];
        loo_before += cur.sse_left_out[j], loo_after += m.sse_left_out[j];
      }
      std::string why;
      if (!(sc.delta_bic < -kBicMargin)) sc.verdict = "BIC drop " + Num(-sc.delta_bic) + " <= " + Num(kBicMargin);
      else if (!enough || !(total_after < total_before))
        sc.verdict = "held-out gain below " + Num(100 * kMinHeldoutGain) + " % where it acts";
      else if (!loo_enough || (loo && !(loo_after < loo_before)))
        sc.verdict = "no gain on whole recordings left out";
      else if (!Admissible(c, m, &why)) sc.verdict = why;
      else sc.verdict = "admissible";
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
    const std::string why = "BIC " + Num(sc.delta_bic) + ", held-out gain hip " + Num(sc.gain_pct[0]) + " %, knee " +
                            Num(sc.gain_pct[1]) + " %" +
                            (loo ? ", left-out recordings hip " + Num(sc.left_out_gain_pct[0]) + " %, knee " +
                                       Num(sc.left_out_gain_pct[1]) + " %"
                                 : "");
    d.steps.push_back({sc.label, why, cur});
    d.selection.push_back("add " + sc.label + " (" + why + "): " + Scores(cur));
  }
  // The calibration: the chosen structure fitted on every sample.
  {
    Loop all(recs, 1.0);
    EmgFitOptions& o = all.options();
    o.autocorr_rows = 0;
    ProfileAll(all, &spec);
    d.calibration = all.Fit(spec);
  }
  // Channels whose fitted alpha contradicts their muscle's action (HJ15 eq. 23-24 signs): crosstalk,
  // a channel standing for a missing muscle, or collinearity; reported, not constrained.
  for (const EmgTerm& t : d.calibration.terms) {
    if (t.kind != TermKind::kAlpha) continue;
    const int expected = t.proxy ? ActionSign(Muscle::kGMAX, t.joint) : ActionSign(t.muscle, t.joint);
    if (t.value * expected < 0 && std::abs(t.value) > 2 * t.se)
      d.notes.push_back(t.Name() + " at the " + kJoint[t.joint] + ": " + Num(t.value) + " +- " + Num(t.se) +
                        " N m, against the " + MuscleName(t.muscle) +
                        "'s action there (crosstalk, a missing muscle's activity, or collinearity)");
  }
  // Plot series of the first recording.
  const EmgRecording& r = *recs[0];
  d.t = r.t;
  d.split = static_cast<size_t>(std::floor((1 - opt.holdout_fraction) * static_cast<double>(r.size())));
  for (int j = 0; j < 2; ++j) {
    d.measured[j] = r.tau[j];
    d.linear[j] = PredictMoment(d.steps.front().model, r, j);
    d.final_[j] = PredictMoment(d.steps.back().model, r, j);
  }
  return d;
}

}  // namespace exotwin
