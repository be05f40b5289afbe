#include "emg/emg_torque_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "diagnosis/diagnose_select.h"
#include "formats/measured_data.h"
#include "formats/number_text.h"
#include "dsp/statistics.h"
#include "core/yaml_fields.h"
#include "core/error.h"
#include "model/passive_torque.h"

namespace exotwin {
namespace {

const char* kJointName[2] = {"hip", "knee"};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return Percentile(v, 0.5);
}

int ChannelIndex(const EmgRecording& rec, const std::string& ch) {
  for (size_t i = 0; i < rec.channels.size(); ++i)
    if (rec.channels[i] == ch) return static_cast<int>(i);
  return -1;
}

}  // namespace

double EmgModelSpec::Delay(Muscle m) const {
  const auto it = delay_s.find(m);
  return it == delay_s.end() ? common_delay : it->second;
}

bool EmgModelSpec::Pooled(Muscle m) const { return std::find(pooled.begin(), pooled.end(), m) != pooled.end(); }

int EmgTorqueModel::nonlinear_parameters() const {
  int n = (spec.a_shape != 0 ? 1 : 0) + (spec.common_delay != 0 ? 1 : 0) + (spec.twitch != 0 ? 1 : 0);
  for (const auto& d : spec.delay_s) n += d.second != 0 ? 1 : 0;
  return n;
}

std::string EmgTerm::Kind() const {
  switch (kind) {
    case TermKind::kAlpha: return "alpha";
    case TermKind::kAlphaQ: return "alpha_q";
    case TermKind::kBeta: return "beta";
    case TermKind::kGamma: return "gamma";
    case TermKind::kOffset: return "offset";
    case TermKind::kPassive: return "passive_scale";
  }
  return "";
}

int EmgTerm::ExpectedSign() const {
  if (kind != TermKind::kAlpha && kind != TermKind::kAlphaQ) return 0;
  return proxy ? ActionSign(Muscle::kGMAX, joint) : ActionSign(muscle, joint);
}

std::string EmgTerm::Name() const {
  if (kind == TermKind::kAlpha || kind == TermKind::kAlphaQ)
    return Kind() + "[" + channel + (proxy ? " as GMAX" : "") + "]";
  return Kind();
}

std::string EmgTerm::Unit() const {
  switch (kind) {
    case TermKind::kAlpha: return "N m";  // per unit envelope (fraction of the muscle's maximum)
    case TermKind::kAlphaQ: return "N m/rad";
    case TermKind::kBeta: return "N m/rad";
    case TermKind::kGamma: return "N m s/rad";
    case TermKind::kOffset: return "N m";
    case TermKind::kPassive: return "1";
  }
  return "";
}

std::vector<EmgTerm> TermsOf(const EmgModelSpec& spec, const EmgRecording& rec) {
  std::vector<EmgTerm> out;
  const bool gmax_missing = std::find(rec.missing.begin(), rec.missing.end(), "GMAX") != rec.missing.end();
  for (int j = 0; j < 2; ++j) {
    std::vector<EmgTerm> alphas;
    for (size_t c = 0; c < rec.channels.size(); ++c) {
      EmgTerm t;
      t.joint = j, t.kind = TermKind::kAlpha, t.channel = rec.channels[c], t.muscle = rec.muscle[c];
      if (spec.Pooled(t.muscle)) {  // one term of the muscle's channels: "a+b"
        bool first = true;
        for (size_t k = 0; k < c; ++k) first &= rec.muscle[k] != t.muscle;
        if (!first) continue;
        for (size_t k = c + 1; k < rec.channels.size(); ++k)
          if (rec.muscle[k] == t.muscle) t.channel += "+" + rec.channels[k];
      }
      if (ActionSign(rec.muscle[c], j) != 0) alphas.push_back(t);
      else if (j == 0 && spec.gmax_proxy && gmax_missing && rec.muscle[c] == Muscle::kVM)
        t.proxy = true, alphas.push_back(t);
    }
    out.insert(out.end(), alphas.begin(), alphas.end());
    if (spec.moment_arm[j])
      for (EmgTerm t : alphas) t.kind = TermKind::kAlphaQ, out.push_back(t);
    for (TermKind k : {TermKind::kBeta, TermKind::kGamma, TermKind::kOffset}) {
      EmgTerm t;
      t.joint = j, t.kind = k;
      out.push_back(t);
    }
    if (spec.passive[j]) {
      EmgTerm t;
      t.joint = j, t.kind = TermKind::kPassive;
      out.push_back(t);
    }
  }
  return out;
}

double ActivationShape(double u, double A) {
  if (A == 0) return u;
  const double den = std::expm1(A);
  if (u < 0) return u * A / den;                                  // a(0) = 0, a'(0) = A / (e^A - 1)
  if (u > 1) return 1 + (u - 1) * A * std::exp(A) / den;          // a(1) = 1, a'(1) = A e^A / (e^A - 1)
  return std::expm1(A * u) / den;
}

std::vector<double> TwitchFilter(const std::vector<double>& t, const std::vector<double>& u, double tau) {
  if (tau <= 0 || u.empty()) return u;
  // Two first-order stages x' = (in - x) / tau, each discretized exactly for an input held over
  // the step: x_i = p x_{i-1} + (1 - p) in_i, p = exp(-dt_i / tau).
  std::vector<double> y(u.size());
  double x1 = u[0], x2 = u[0];
  for (size_t i = 0; i < u.size(); ++i) {
    const double p = i ? std::exp(-(t[i] - t[i - 1]) / tau) : 1.0;
    x1 = p * x1 + (1 - p) * u[i];
    x2 = p * x2 + (1 - p) * x1;
    y[i] = x2;
  }
  return y;
}

std::vector<double> ChannelEnvelope(const EmgRecording& rec, const std::string& channel) {
  std::vector<double> sum(rec.size(), 0.0);
  int n = 0;
  for (size_t a = 0; a <= channel.size();) {
    size_t b = channel.find('+', a);
    if (b == std::string::npos) b = channel.size();
    const std::string name = channel.substr(a, b - a);
    const int c = ChannelIndex(rec, name);
    if (c < 0) throw InputError(rec.source + ": no EMG channel '" + name + "' (the model uses it)");
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += rec.e[c][i];
    ++n, a = b + 1;
  }
  for (double& v : sum) v /= n;
  return sum;
}

namespace {

// Riener & Edrich's passive moment along coordinate j, with the calibration's range of the spec.
double PassiveAlong(const EmgModelSpec& spec, int j, double q0, double q1) {
  return spec.bounded ? PassiveMomentAlong(j, q0, q1, spec.q_lo, spec.q_hi) : PassiveMomentAlong(j, q0, q1);
}

}  // namespace

double PassiveMomentAlong(int j, double q0, double q1, const double* q_lo, const double* q_hi) {
  auto P = [j](double a, double b) {
    return -PassiveElasticTorque(PassiveModel::kRiener1999, Eigen::Vector2d(a, b))[j];
  };
  if (!q_lo || !q_hi) return P(q0, q1);
  const double c0 = std::clamp(q0, q_lo[0], q_hi[0]), c1 = std::clamp(q1, q_lo[1], q_hi[1]);
  if (c0 == q0 && c1 == q1) return P(q0, q1);
  constexpr double h = 1e-4;  // rad: central differences of a smooth sum of exponentials
  return P(c0, c1) + (P(c0 + h, c1) - P(c0 - h, c1)) / (2 * h) * (q0 - c0) +
         (P(c0, c1 + h) - P(c0, c1 - h)) / (2 * h) * (q1 - c1);
}

std::vector<double> TermColumn(const EmgTerm& term, const EmgModelSpec& spec, const EmgRecording& rec) {
  const size_t n = rec.size();
  const int j = term.joint;
  std::vector<double> v(n);
  if (term.kind == TermKind::kAlpha || term.kind == TermKind::kAlphaQ) {
    std::vector<double> u = ChannelEnvelope(rec, term.channel);
    const double d = spec.Delay(term.muscle);
    if (d != 0) {
      std::vector<double> tq(n);
      for (size_t i = 0; i < n; ++i) tq[i] = rec.t[i] - d;
      u = Interpolate(rec.t, u, tq);
    }
    u = TwitchFilter(rec.t, u, spec.twitch);
    for (size_t i = 0; i < n; ++i) {
      double q = rec.q[j][i];
      if (spec.bounded) q = std::clamp(q, spec.q_lo[j], spec.q_hi[j]);
      v[i] = ActivationShape(u[i], spec.a_shape) * (term.kind == TermKind::kAlphaQ ? q : 1.0);
    }
    return v;
  }
  for (size_t i = 0; i < n; ++i) {
    switch (term.kind) {
      case TermKind::kBeta: v[i] = rec.q[j][i]; break;
      case TermKind::kGamma: v[i] = rec.qd[j][i]; break;
      case TermKind::kOffset: v[i] = 1.0; break;
      case TermKind::kPassive:  // P of HJ15 eq. 1 is minus the passive moment along the coordinate
        v[i] = PassiveAlong(spec, j, rec.q[0][i], rec.q[1][i]);
        break;
      default: break;
    }
  }
  return v;
}

namespace {

// Another gait at joint j (kOtherGaitShare), and the share behind the answer.
bool OtherGait(const EmgTorqueModel& model, const EmgRecording& rec, int joint, double* share) {
  *share = model.range.empty() ? 0.0 : JointOutsideShare(model.range, rec, joint, model.spec.gmax_proxy);
  return !model.papers_terms.empty() && !model.range.empty() && *share > kOtherGaitShare;
}

std::vector<double> PapersMoment(const EmgTorqueModel& model, const EmgRecording& rec, int joint) {
  EmgTorqueModel papers;  // the papers' form: the default structure
  papers.terms = model.papers_terms;
  return PredictLinearMoment(papers, rec, joint);
}

}  // namespace

std::vector<double> PredictMoment(const EmgTorqueModel& model, const EmgRecording& rec, int joint) {
  double share;
  if (OtherGait(model, rec, joint, &share)) return PapersMoment(model, rec, joint);
  if (!(model.msk.present && model.msk_form[joint])) return PredictLinearMoment(model, rec, joint);
  return PredictMoments(model, rec).tau[joint];
}

EmgPrediction PredictMoments(const EmgTorqueModel& model, const EmgRecording& rec) {
  EmgPrediction p;
  const bool any = model.msk.present && (model.msk_form[0] || model.msk_form[1]);
  if (model.msk.present) p.msk = MskSeries(model.msk, rec);  // the muscle states, reported either way
  for (int j = 0; j < 2; ++j) {
    p.tau[j] = PredictLinearMoment(model, rec, j);
    p.fallback[j].assign(rec.size(), 0);
    p.papers[j] = OtherGait(model, rec, j, &p.outside_share[j]);
    if (p.papers[j]) {
      p.tau[j] = PapersMoment(model, rec, j);
      continue;
    }
    if (!(any && model.msk_form[j])) continue;
    double n = 0;
    for (size_t i = 0; i < rec.size(); ++i) {
      if (p.msk.outside[j][i]) p.fallback[j][i] = 1, n += 1;
      else p.tau[j][i] = p.msk.tau[j][i];
    }
    p.fallback_share[j] = rec.size() ? n / static_cast<double>(rec.size()) : 0;
  }
  return p;
}

std::vector<double> PredictLinearMoment(const EmgTorqueModel& model, const EmgRecording& rec, int joint) {
  std::vector<double> tau(rec.size(), 0.0);
  for (const EmgTerm& t : model.terms) {
    if (t.joint != joint) continue;
    const std::vector<double> col = TermColumn(t, model.spec, rec);
    for (size_t i = 0; i < tau.size(); ++i) tau[i] += t.value * col[i];
  }
  return tau;
}

std::vector<size_t> WithinSpikeLimit(const std::vector<double>& x, size_t a, size_t b) {
  std::vector<size_t> idx;
  if (b <= a) return idx;
  const std::vector<double> part(x.begin() + static_cast<long>(a), x.begin() + static_cast<long>(b));
  const double med = Median(part);
  std::vector<double> dev(part.size());
  for (size_t i = 0; i < part.size(); ++i) dev[i] = std::abs(part[i] - med);
  const double limit = kSpikeMads * 1.4826 * Median(dev);
  for (size_t i = a; i < b; ++i)
    if (std::abs(x[i] - med) <= limit) idx.push_back(i);
  return idx;
}

void ScoreSamples(const std::vector<double>& measured, const std::vector<double>& predicted,
                  const std::vector<size_t>& idx, double* r2, double* rms) {
  double mean = 0, ss_res = 0, ss_tot = 0;
  for (size_t i : idx) mean += measured[i];
  mean /= std::max<size_t>(1, idx.size());
  for (size_t i : idx) ss_res += std::pow(measured[i] - predicted[i], 2), ss_tot += std::pow(measured[i] - mean, 2);
  *r2 = ss_tot > 0 ? 1 - ss_res / ss_tot : 0;
  *rms = idx.empty() ? 0 : std::sqrt(ss_res / static_cast<double>(idx.size()));
}

EmgTorqueModel FitEmgModel(const EmgModelSpec& spec, const std::vector<const EmgRecording*>& recs,
                           const EmgFitOptions& opt) {
  if (recs.empty()) throw InputError("emg fit: no recording");
  EmgTorqueModel model;
  model.spec = spec;
  model.missing = recs[0]->missing;
  model.terms = TermsOf(spec, *recs[0]);
  for (const EmgRecording* r : recs) {
    if (!r->has_moments()) throw InputError(r->source + ": no joint moments to fit (--moments)");
    if (r->channels != recs[0]->channels)
      throw InputError(r->source + ": its EMG channels differ from those of " + recs[0]->source +
                       " (every recording of one fit needs the same mapped channels)");
  }
  const size_t T = model.terms.size();
  auto n_train = [&](const EmgRecording& r) {
    return std::min(r.size(), static_cast<size_t>(std::floor(opt.train_fraction * static_cast<double>(r.size()))));
  };
  // Rows kept per recording and joint: fit rows (all, or within the spike limit when robust) and
  // held-out rows within the spike limit.
  std::vector<std::vector<char>> keep[2];
  for (int j = 0; j < 2; ++j)
    for (const EmgRecording* r : recs) {
      const size_t m = r->size(), mtr = n_train(*r);
      std::vector<char> k(m, 0);
      if (spec.robust) for (size_t i : WithinSpikeLimit(r->tau[j], 0, mtr)) k[i] = 1;
      else std::fill(k.begin(), k.begin() + static_cast<long>(mtr), 1);
      for (size_t i : WithinSpikeLimit(r->tau[j], mtr, m)) k[i] = 1;
      keep[j].push_back(std::move(k));
    }
  double w[2] = {opt.weight[0], opt.weight[1]};
  for (int j = 0; j < 2; ++j) {
    if (w[j] > 0) continue;
    double s = 0, ss = 0, n = 0;
    for (size_t k = 0; k < recs.size(); ++k)
      for (size_t i = 0; i < n_train(*recs[k]); ++i)
        if (keep[j][k][i]) s += recs[k]->tau[j][i], ss += recs[k]->tau[j][i] * recs[k]->tau[j][i], n += 1;
    const double var = n > 1 ? (ss - s * s / n) / (n - 1) : 0;
    if (!(var > 0)) throw InputError(recs[0]->source + ": the " + kJointName[j] + " moment is constant");
    w[j] = 1 / std::sqrt(var);
  }
  // Cross-validation folds: the recordings, or contiguous blocks of the one recording.
  struct Fold {
    size_t rec, a, b;
  };
  std::vector<Fold> folds;
  model.folds_are_recordings = recs.size() >= 2;
  if (model.folds_are_recordings) {
    for (size_t k = 0; k < recs.size(); ++k) folds.push_back({k, 0, recs[k]->size()});
  } else {
    const size_t m = recs[0]->size(), K = static_cast<size_t>(std::max(1, opt.blocks));
    for (size_t f = 0; f < K; ++f) folds.push_back({0, f * m / K, (f + 1) * m / K});
  }
  // Unweighted columns per recording (for predictions), and the Gram matrices of the weighted
  // columns (diagnose_select.h Grams: fit rows pooled, held-out rows per joint, and each fold's rows)
  // accumulated from them directly: a column enters only the rows of its joint, rows left out
  // (keep) count as zero rows.
  std::vector<std::vector<std::vector<double>>> cols(recs.size());
  for (size_t k = 0; k < recs.size(); ++k)
    for (const EmgTerm& t : model.terms) cols[k].push_back(TermColumn(t, spec, *recs[k]));
  Grams g;
  {
    const Eigen::Index C = static_cast<Eigen::Index>(T);
    g.Gtr = Eigen::MatrixXd::Zero(C, C), g.btr = Eigen::VectorXd::Zero(C);
    for (int j = 0; j < 2; ++j) g.Gte[j] = Eigen::MatrixXd::Zero(C, C), g.bte[j] = Eigen::VectorXd::Zero(C);
    std::vector<size_t> of[2];  // the columns of each joint
    for (size_t c = 0; c < T; ++c) of[model.terms[c].joint].push_back(c);
    // Row factor w_j^2 of each joint's rows, zero where a row is left out.
    std::vector<double> m2[2];
    auto dot = [](const std::vector<double>& m, const std::vector<double>& u, const std::vector<double>& v,
                  size_t lo, size_t hi) {
      double s = 0;
      for (size_t i = lo; i < hi; ++i) s += m[i] * u[i] * v[i];
      return s;
    };
    size_t cur = recs.size();
    for (const Fold& fo : folds) {
      const EmgRecording& r = *recs[fo.rec];
      if (fo.rec != cur) {
        cur = fo.rec;
        for (int j = 0; j < 2; ++j) {
          m2[j].resize(r.size());
          for (size_t i = 0; i < r.size(); ++i) m2[j][i] = keep[j][cur][i] ? w[j] * w[j] : 0.0;
        }
      }
      const std::vector<std::vector<double>>& x = cols[cur];
      const size_t mtr = std::clamp(n_train(r), fo.a, fo.b);
      for (int j = 0; j < 2; ++j) {
        Eigen::MatrixXd Gt = Eigen::MatrixXd::Zero(C, C), Ge = Eigen::MatrixXd::Zero(C, C);
        Eigen::VectorXd bt = Eigen::VectorXd::Zero(C), be = Eigen::VectorXd::Zero(C);
        for (size_t a = 0; a < of[j].size(); ++a) {
          const size_t ca = of[j][a];
          bt[static_cast<Eigen::Index>(ca)] = dot(m2[j], x[ca], r.tau[j], fo.a, mtr);
          be[static_cast<Eigen::Index>(ca)] = dot(m2[j], x[ca], r.tau[j], mtr, fo.b);
          for (size_t b2 = 0; b2 <= a; ++b2) {
            const size_t cb = of[j][b2];
            const Eigen::Index ia = static_cast<Eigen::Index>(ca), ib = static_cast<Eigen::Index>(cb);
            Gt(ia, ib) = Gt(ib, ia) = dot(m2[j], x[ca], x[cb], fo.a, mtr);
            Ge(ia, ib) = Ge(ib, ia) = dot(m2[j], x[ca], x[cb], mtr, fo.b);
          }
        }
        const double rt = dot(m2[j], r.tau[j], r.tau[j], fo.a, mtr), re = dot(m2[j], r.tau[j], r.tau[j], mtr, fo.b);
        g.Gtr += Gt, g.btr += bt, g.rrtr += rt;
        g.Gte[j] += Ge, g.bte[j] += be, g.rrte[j] += re;
        g.Grec[j].push_back(Gt + Ge);
        g.brec[j].push_back(bt + be);
        g.rrrec[j].push_back(rt + re);
      }
    }
  }
  // Fit rows actually used (zero-weight rows do not count).
  double rows = 0;
  for (int j = 0; j < 2; ++j)
    for (size_t k = 0; k < recs.size(); ++k)
      for (size_t i = 0; i < n_train(*recs[k]); ++i) rows += keep[j][k][i];
  g.n_tr = rows;
  std::vector<int> all(T);
  for (size_t c = 0; c < T; ++c) all[c] = static_cast<int>(c);
  auto predict = [&](const Eigen::VectorXd& coef, size_t k, int j) {
    std::vector<double> p(recs[k]->size(), 0.0);
    for (size_t c = 0; c < T; ++c)
      if (model.terms[c].joint == j)
        for (size_t i = 0; i < p.size(); ++i) p[i] += coef[static_cast<Eigen::Index>(c)] * cols[k][c][i];
    return p;
  };
  // With spec.signed_alphas every alpha keeps its muscle's sign (EmgTerm::ExpectedSign): the
  // sign-constrained fit, the alphas it holds at zero marked `held`.
  std::vector<int> sign(T, 0);
  if (spec.signed_alphas)
    for (size_t c = 0; c < T; ++c)
      if (model.terms[c].kind == TermKind::kAlpha) sign[c] = model.terms[c].ExpectedSign();
  Eigen::VectorXd coef, se;
  auto fit = [&] {
    const Fit r = spec.signed_alphas ? FitColsSigned(g, all, sign) : FitCols(g, all);
    coef = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(T)), se = coef;
    for (size_t k = 0; k < r.cols.size() && r.ok; ++k)
      coef[r.cols[k]] = r.coef[static_cast<Eigen::Index>(k)], se[r.cols[k]] = r.se[static_cast<Eigen::Index>(k)];
    return r;
  };
  double L = opt.autocorr_rows;
  g.n_eff = g.n_tr / std::max(1.0, L);
  Fit f = fit();
  if (!f.ok)
    throw InputError(recs[0]->source + ": the model's regressors are nearly collinear (a channel that "
                     "is constant or copies another?)");
  if (!(L > 0)) {  // autocorrelation length of the fit residual, longest over joints and recordings
    L = 1;
    for (size_t k = 0; k < recs.size(); ++k)
      for (int j = 0; j < 2; ++j) {
        const std::vector<double> p = predict(coef, k, j);
        std::vector<double> res;
        for (size_t i = 0; i < n_train(*recs[k]); ++i)
          if (keep[j][k][i]) res.push_back(recs[k]->tau[j][i] - p[i]);
        if (res.size() > 8) L = std::max(L, AutocorrelationLength(res.data(), res.size()));
      }
    g.n_eff = g.n_tr / L;
    f = fit();
  }
  model.autocorr_rows = L;
  model.weight[0] = w[0], model.weight[1] = w[1];
  for (size_t c = 0; c < T; ++c) {
    EmgTerm& t = model.terms[c];
    t.value = coef[static_cast<Eigen::Index>(c)], t.se = se[static_cast<Eigen::Index>(c)];
    t.held = sign[c] != 0 && std::find(f.cols.begin(), f.cols.end(), static_cast<int>(c)) == f.cols.end();
  }
  model.bic = f.bic + model.nonlinear_parameters() * std::log(g.n_eff);
  model.sse_fit = f.sse_tr, model.n_fit = g.n_tr;
  if (opt.fit_only) return model;
  for (int j = 0; j < 2; ++j) model.sse_heldout[j] = f.sse_te_j[j];
  model.range = RangeOf(recs);
  // Cross-validation: each fold predicted by the coefficients fitted on the others' rows, scored on
  // its samples within kSpikeMads of the recording's median moment.
  {
    std::vector<std::vector<char>> score[2];
    for (int j = 0; j < 2; ++j)
      for (const EmgRecording* r : recs) {
        std::vector<char> k(r->size(), 0);
        for (size_t i : WithinSpikeLimit(r->tau[j], 0, r->size())) k[i] = 1;
        score[j].push_back(std::move(k));
      }
    std::vector<double> meas[2], res[2];
    for (size_t fi = 0; fi < folds.size() && folds.size() >= 2; ++fi) {
      const Fold& fo = folds[fi];
      const Eigen::VectorXd x = spec.signed_alphas ? FitLeavingOutSigned(g, all, sign, fi) : FitLeavingOut(g, all, fi);
      std::array<double, 2> sse = {0, 0};
      for (int j = 0; j < 2; ++j)
        for (size_t i = fo.a; i < fo.b; ++i) {
          if (!score[j][fo.rec][i]) continue;
          double p = 0;
          for (size_t c = 0; c < T && x.size() > 0; ++c)
            if (model.terms[c].joint == j) p += x[static_cast<Eigen::Index>(c)] * cols[fo.rec][c][i];
          const double e = x.size() > 0 ? recs[fo.rec]->tau[j][i] - p : 1e150;  // unidentifiable without it
          sse[j] += w[j] * w[j] * e * e;
          meas[j].push_back(recs[fo.rec]->tau[j][i]), res[j].push_back(e);
        }
      model.sse_fold.push_back(sse);
      for (int j = 0; j < 2; ++j) model.sse_cv[j] += sse[j];
    }
    for (int j = 0; j < 2; ++j) {
      std::vector<double> pred(res[j].size());
      std::vector<size_t> idx(res[j].size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = i, pred[i] = meas[j][i] - res[j][i];
      ScoreSamples(meas[j], pred, idx, &model.figures[j].r2_cv, &model.figures[j].rms_cv);
    }
  }
  // Figures pooled over recordings.
  for (int j = 0; j < 2; ++j) {
    std::vector<double> mf, pf, mh, ph, mt, pt;
    EmgJointFigures& F = model.figures[j];
    for (size_t k = 0; k < recs.size(); ++k) {
      const std::vector<double> p = predict(coef, k, j);
      const std::vector<double>& tau = recs[k]->tau[j];
      const size_t m = tau.size(), mtr = n_train(*recs[k]);
      for (size_t i = 0; i < m; ++i) {
        if (i < mtr && keep[j][k][i]) mf.push_back(tau[i]), pf.push_back(p[i]);
        if (i >= mtr) {
          mh.push_back(tau[i]), ph.push_back(p[i]);
          if (keep[j][k][i]) mt.push_back(tau[i]), pt.push_back(p[i]);
        }
      }
    }
    auto score = [](const std::vector<double>& a, const std::vector<double>& b, double* r2, double* rms) {
      std::vector<size_t> idx(a.size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
      ScoreSamples(a, b, idx, r2, rms);
    };
    double rms_fit = 0;
    score(mf, pf, &F.r2_fit, &rms_fit);
    score(mh, ph, &F.r2_heldout, &F.rms_heldout);
    score(mt, pt, &F.r2_heldout_trim, &F.rms_heldout_trim);
    F.heldout = mh.size(), F.trimmed = mh.size() - mt.size();
  }
  return model;
}

EmgCalibrationRange RangeOf(const std::vector<const EmgRecording*>& recs) {
  EmgCalibrationRange g;
  if (recs.empty()) return g;
  g.channels = recs[0]->channels;
  g.e_lo.assign(g.channels.size(), 1e300), g.e_hi.assign(g.channels.size(), -1e300);
  for (int j = 0; j < 2; ++j) g.q_lo[j] = g.qd_lo[j] = 1e300, g.q_hi[j] = g.qd_hi[j] = -1e300;
  for (const EmgRecording* r : recs) {
    for (size_t c = 0; c < g.channels.size(); ++c) {
      const auto mm = std::minmax_element(r->e[c].begin(), r->e[c].end());
      g.e_lo[c] = std::min(g.e_lo[c], *mm.first), g.e_hi[c] = std::max(g.e_hi[c], *mm.second);
    }
    for (int j = 0; j < 2; ++j) {
      const auto q = std::minmax_element(r->q[j].begin(), r->q[j].end());
      const auto qd = std::minmax_element(r->qd[j].begin(), r->qd[j].end());
      g.q_lo[j] = std::min(g.q_lo[j], *q.first), g.q_hi[j] = std::max(g.q_hi[j], *q.second);
      g.qd_lo[j] = std::min(g.qd_lo[j], *qd.first), g.qd_hi[j] = std::max(g.qd_hi[j], *qd.second);
    }
  }
  return g;
}

EmgExtrapolation ExtrapolationOf(const EmgCalibrationRange& g, const EmgRecording& rec) {
  EmgExtrapolation x;
  const double n = static_cast<double>(std::max<size_t>(1, rec.size()));
  auto share = [n](const std::vector<double>& v, double lo, double hi) {
    double out = 0;
    for (double y : v) out += (y < lo || y > hi) ? 1 : 0;
    return out / n;
  };
  for (size_t c = 0; c < rec.channels.size(); ++c) {
    x.channels.push_back(rec.channels[c]);
    const auto it = std::find(g.channels.begin(), g.channels.end(), rec.channels[c]);
    if (it == g.channels.end()) {
      x.envelope_share.push_back(1.0);
      continue;
    }
    const size_t k = static_cast<size_t>(it - g.channels.begin());
    x.envelope_share.push_back(share(rec.e[c], g.e_lo[k], g.e_hi[k]));
  }
  for (int j = 0; j < 2; ++j) {
    x.angle_share[j] = share(rec.q[j], g.q_lo[j], g.q_hi[j]);
    x.velocity_share[j] = share(rec.qd[j], g.qd_lo[j], g.qd_hi[j]);
  }
  return x;
}

double JointOutsideShare(const EmgCalibrationRange& g, const EmgRecording& rec, int joint, bool gmax_proxy) {
  if (rec.size() == 0) return 0.0;
  std::vector<char> out(rec.size(), 0);
  auto mark = [&](const std::vector<double>& v, double lo, double hi) {
    for (size_t i = 0; i < v.size() && i < out.size(); ++i) out[i] |= (v[i] < lo || v[i] > hi) ? 1 : 0;
  };
  for (int k = 0; k < 2; ++k) mark(rec.q[k], g.q_lo[k], g.q_hi[k]), mark(rec.qd[k], g.qd_lo[k], g.qd_hi[k]);
  for (size_t c = 0; c < rec.channels.size(); ++c) {
    const Muscle m = rec.muscle[c];
    if (ActionSign(m, joint) == 0 && !(gmax_proxy && joint == 0 && m == Muscle::kVM)) continue;
    const auto it = std::find(g.channels.begin(), g.channels.end(), rec.channels[c]);
    if (it == g.channels.end()) continue;  // not an input of the calibrated model
    const size_t k = static_cast<size_t>(it - g.channels.begin());
    mark(rec.e[c], g.e_lo[k], g.e_hi[k]);
  }
  double n = 0;
  for (char o : out) n += o;
  return n / static_cast<double>(rec.size());
}

// ---- EMGMODEL.yaml ----

namespace {

// The musculoskeletal block: the form per joint and every muscle's parameters with bounds and sources.
std::string EmgMskYaml(const EmgTorqueModel& em) {
  const EmgMskModel& m = em.msk;
  std::ostringstream o;
  auto num = [](double v) { return NumberText(v, 17); };  // read back exactly (the state ranges' ends)
  auto form = [&](int j) { return em.msk_form[j] ? "musculoskeletal" : "linear"; };
  o << "# The musculoskeletal form (emg/emg_msk_model.h): per channel one Hill unit (Thelen 2003 curves, its\n"
       "# tendon as `tendon` says) on a gait2392 path (Delp et al. 1990; hip, knee and the recording's ankle),\n"
       "# force s F_max (a f_L f_V + f_PE) cos(phi) acting at every joint the path crosses with its moment arm\n"
       "# -dL/dq; plus beta q + gamma qd + offset + passive_scale M_P(q) per joint (M_P Riener & Edrich 1999,\n"
       "# along its tangent outside angle_range). Bounds of CEINMS-RT's calibration (strength 0.5-1.5, l_ts\n"
       "# +-5 %, l_opt +-2.5 % of the scaled gait2392 values).\n";
  o << "forms: {hip: " << form(0) << ", knee: " << form(1) << "}\n";
  o << "musculoskeletal:\n";
  o << "  tendon: " << (m.elastic_tendon ? "elastic" : "rigid") << "   # elastic: Thelen 2003's f_T in series\n";
  o << "  activation: {delay: {value: " << num(m.delay) << ", bounds: [0.01, 0.1], unit: s, source: \"Cavanagh & Komi 1979\"}, "
    << "twitch: {value: " << num(m.twitch) << ", unit: s, source: \"the linear loop's twitch\"}, A_shape: {value: "
    << num(m.a_shape) << ", bounds: [-3, 0], unit: \"1\", source: \"LB03 eq. 2; CEINMS-RT bounds\"}}\n";
  o << "  remainder:\n";
  for (int j = 0; j < 2; ++j)
    o << "    " << kJointName[j] << ": {beta: " << num(m.beta[j]) << ", gamma: " << num(m.gamma[j]) << ", offset: "
      << num(m.offset[j]) << ", passive_scale: " << num(m.passive_scale[j]) << ", angle_range: [" << num(m.q_lo[j]) << ", "
      << num(m.q_hi[j]) << "], units: [\"N m/rad\", \"N m s/rad\", \"N m\", \"1 (x Riener & Edrich 1999)\", rad]}\n";
  o << "  reachable_share: {hip: " << NumberText(m.reachable_share[0], 4) << ", knee: " << NumberText(m.reachable_share[1], 4)
    << "}\n";
  o << "  reachable_share_recorded: {hip: " << NumberText(m.reachable_share_recorded[0], 4)
    << ", knee: " << NumberText(m.reachable_share_recorded[1], 4) << "}\n";
  o << "  fit: {hip: {r2_cv: " << NumberText(m.r2_cv[0], 4) << ", rms_cv: " << NumberText(m.rms_cv[0], 4) << ", r2_fit: "
    << NumberText(m.r2_fit[0], 4) << "}, knee: {r2_cv: " << NumberText(m.r2_cv[1], 4) << ", rms_cv: "
    << NumberText(m.rms_cv[1], 4) << ", r2_fit: " << NumberText(m.r2_fit[1], 4) << "}}\n";
  o << "  muscles:\n";
  for (const EmgMskMuscle& x : m.muscles) {
    const MusculotendonParams& n = x.nominal;
    o << "    - channel: " << x.channel << "\n      muscle: " << MuscleName(x.muscle) << "\n";
    if (x.synthesized)
      o << "      synthesized: true   # an unrecorded muscle's term: activation w a(channel), w = strength "
           "(synergy extrapolation, Ao et al. 2020); rigid tendon, active force only\n";
    o << "      path: \"" << MusculotendonPathSource(x.muscle) << "\"\n      actuator: " << n.name << "\n";
    o << "      max_isometric_force: {value: " << num(n.f_max) << ", unit: N, source: \"gait2392 " << n.name << "\"}\n";
    o << "      pennation: {value: " << num(n.pennation) << ", unit: rad, source: \"gait2392, of the path\"}\n";
    o << "      strength: {value: " << num(x.strength) << ", bounds: [" << num(x.strength_lo) << ", " << num(x.strength_hi)
      << "], unit: \"x F_max\", source: \""
      << (x.synthesized ? "synergy weight x strength, >= 0 (Ao et al. 2020), at most CEINMS-RT's upper bound"
                        : "CEINMS-RT calibration bounds")
      << "\"}\n";
    o << "      tendon_slack_length: {value: " << num(x.l_ts) << ", nominal: " << num(n.l_ts) << ", bounds: ["
      << num((1 - kTendonSlackChange) * n.l_ts) << ", " << num((1 + kTendonSlackChange) * n.l_ts)
      << "], unit: m, source: \"gait2392 scaled to the path (Delp et al. 2007); +-5 % CEINMS-RT\"}\n";
    o << "      optimal_fibre_length: {value: " << num(x.l_opt) << ", nominal: " << num(n.l_opt) << ", bounds: ["
      << num((1 - kOptimalFibreChange) * n.l_opt) << ", " << num((1 + kOptimalFibreChange) * n.l_opt)
      << "], unit: m, source: \"gait2392 scaled to the path (Delp et al. 2007); +-2.5 % CEINMS-RT\"}\n";
    o << "      calibrated_state: {fibre_length: [" << NumberText(x.fibre_lo, 17) << ", " << NumberText(x.fibre_hi, 17)
      << "], fibre_velocity: [" << NumberText(x.velocity_lo, 17) << ", " << NumberText(x.velocity_hi, 17)
      << "], units: [l_opt, \"10 l_opt/s\"]}\n";
  }
  return o.str();
}

// Reads the musculoskeletal block (EmgMskYaml) into m; every parameter inside its bounds.
void ReadEmgMsk(const YamlContext& c, const YAML::Node& root, EmgTorqueModel* em) {
  const YAML::Node f = root["forms"], k = root["musculoskeletal"];
  if (!f && !k) return;
  if (!f || !k) c.Fail(f ? "musculoskeletal" : "forms", "expected both forms: and musculoskeletal: (a file written by emg-fit)");
  for (int j = 0; j < 2; ++j) {
    const YAML::Node v = f[kJointName[j]];
    const std::string key = std::string("forms.") + kJointName[j];
    if (!v || !v.IsScalar() || (v.as<std::string>() != "linear" && v.as<std::string>() != "musculoskeletal"))
      c.Fail(key, "expected linear or musculoskeletal" + YamlLine(v));
    em->msk_form[j] = v.as<std::string>() == "musculoskeletal";
  }
  EmgMskModel& m = em->msk;
  m.elastic_tendon = false;  // files written before the elastic tendon
  if (const YAML::Node td = k["tendon"]) {
    if (!td.IsScalar() || (td.as<std::string>() != "elastic" && td.as<std::string>() != "rigid"))
      c.Fail("musculoskeletal.tendon", "expected elastic or rigid" + YamlLine(td));
    m.elastic_tendon = td.as<std::string>() == "elastic";
  }
  const YAML::Node a = k["activation"];
  m.delay = YamlNumber(c, a["delay"]["value"], "musculoskeletal.activation.delay.value", 0.01, 0.1, "s");
  m.twitch = YamlNumber(c, a["twitch"]["value"], "musculoskeletal.activation.twitch.value", 0, 1, "s");
  m.a_shape = YamlNumber(c, a["A_shape"]["value"], "musculoskeletal.activation.A_shape.value", -3, 0, "");
  for (int j = 0; j < 2; ++j) {
    const std::string key = std::string("musculoskeletal.remainder.") + kJointName[j];
    const YAML::Node r = k["remainder"][kJointName[j]];
    m.beta[j] = YamlNumber(c, r["beta"], key + ".beta", -1e6, 1e6, "N m/rad");
    m.gamma[j] = YamlNumber(c, r["gamma"], key + ".gamma", -1e6, 1e6, "N m s/rad");
    m.offset[j] = YamlNumber(c, r["offset"], key + ".offset", -1e6, 1e6, "N m");
    // Files written before the passive term: none (and no angle range).
    if (r["passive_scale"]) m.passive_scale[j] = YamlNumber(c, r["passive_scale"], key + ".passive_scale", -100, 100, "");
    if (const YAML::Node ar = r["angle_range"]) {
      if (!ar.IsSequence() || ar.size() != 2) c.Fail(key + ".angle_range", "expected [low, high] (rad)" + YamlLine(ar));
      m.q_lo[j] = YamlNumber(c, ar[0], key + ".angle_range[0]", -kMaxHumanJointAngle, kMaxHumanJointAngle, "rad");
      m.q_hi[j] = YamlNumber(c, ar[1], key + ".angle_range[1]", m.q_lo[j], kMaxHumanJointAngle, "rad");
    }
    if (k["reachable_share"]) m.reachable_share[j] = YamlNumber(c, k["reachable_share"][kJointName[j]], "musculoskeletal.reachable_share." + std::string(kJointName[j]), 0, 1, "");
    if (k["reachable_share_recorded"])
      m.reachable_share_recorded[j] = YamlNumber(c, k["reachable_share_recorded"][kJointName[j]],
                                                 "musculoskeletal.reachable_share_recorded." + std::string(kJointName[j]), 0, 1, "");
  }
  const YAML::Node ms = k["muscles"];
  if (!ms || !ms.IsSequence() || ms.size() == 0) c.Fail("musculoskeletal.muscles", "expected a list of muscles" + YamlLine(ms));
  for (size_t i = 0; i < ms.size(); ++i) {
    const YAML::Node e = ms[i];
    const std::string key = "musculoskeletal.muscles[" + std::to_string(i) + "]";
    EmgMskMuscle x;
    if (!e["channel"] || !e["channel"].IsScalar()) c.Fail(key + ".channel", "expected the EMG channel's name" + YamlLine(e));
    x.channel = e["channel"].as<std::string>();
    if (!e["muscle"] || !MuscleByName(e["muscle"].as<std::string>(), &x.muscle))
      c.Fail(key + ".muscle", "expected GMAX, VM, RF, ST or GAS (a path of sim/musculotendon.h)" + YamlLine(e["muscle"]));
    if (const YAML::Node sy = e["synthesized"]) {
      if (!sy.IsScalar() || (sy.as<std::string>() != "true" && sy.as<std::string>() != "false"))
        c.Fail(key + ".synthesized", "expected true or false" + YamlLine(sy));
      x.synthesized = sy.as<std::string>() == "true";
    }
    x.nominal = ScaledMusculotendon(x.muscle, GenericMusculotendon(x.muscle));
    x.nominal.name = e["actuator"] ? e["actuator"].as<std::string>() : x.nominal.name;
    // Physiology: a force of one human muscle (Delp 1990's largest: soleus 3549 N, x 1.5), pennation
    // below 45 deg, the calibration's own bounds.
    x.nominal.f_max = YamlNumber(c, e["max_isometric_force"]["value"], key + ".max_isometric_force.value", 10, 6000, "N");
    x.nominal.pennation = YamlNumber(c, e["pennation"]["value"], key + ".pennation.value", 0, 0.7854, "rad");
    const YAML::Node sb = e["strength"]["bounds"];
    if (!sb || !sb.IsSequence() || sb.size() != 2) c.Fail(key + ".strength.bounds", "expected [low, high]" + YamlLine(sb));
    x.strength_lo = YamlNumber(c, sb[0], key + ".strength.bounds[0]", x.synthesized ? kSynthesizedStrengthLo : kStrengthLo,
                               kStrengthHi, "x F_max");
    x.strength_hi = YamlNumber(c, sb[1], key + ".strength.bounds[1]", x.strength_lo, kStrengthHi, "x F_max");
    x.strength = YamlNumber(c, e["strength"]["value"], key + ".strength.value", x.strength_lo, x.strength_hi, "x F_max");
    x.nominal.l_ts = YamlNumber(c, e["tendon_slack_length"]["nominal"], key + ".tendon_slack_length.nominal", 0.005, 0.6, "m");
    x.nominal.l_opt = YamlNumber(c, e["optimal_fibre_length"]["nominal"], key + ".optimal_fibre_length.nominal", 0.02, 0.5, "m");
    x.l_ts = YamlNumber(c, e["tendon_slack_length"]["value"], key + ".tendon_slack_length.value",
                        (1 - kTendonSlackChange) * x.nominal.l_ts * (1 - 1e-9), (1 + kTendonSlackChange) * x.nominal.l_ts * (1 + 1e-9), "m");
    x.l_opt = YamlNumber(c, e["optimal_fibre_length"]["value"], key + ".optimal_fibre_length.value",
                         (1 - kOptimalFibreChange) * x.nominal.l_opt * (1 - 1e-9), (1 + kOptimalFibreChange) * x.nominal.l_opt * (1 + 1e-9), "m");
    const YAML::Node st = e["calibrated_state"];
    double fl[2], fv[2];
    for (int b = 0; b < 2; ++b) {
      fl[b] = YamlNumber(c, st["fibre_length"][b], key + ".calibrated_state.fibre_length[" + std::to_string(b) + "]", 0, 3, "l_opt");
      fv[b] = YamlNumber(c, st["fibre_velocity"][b], key + ".calibrated_state.fibre_velocity[" + std::to_string(b) + "]", -1, 1, "v_max");
    }
    x.fibre_lo = fl[0], x.fibre_hi = fl[1], x.velocity_lo = fv[0], x.velocity_hi = fv[1];
    m.muscles.push_back(x);
  }
  m.present = true;
}

}  // namespace

std::string EmgModelYaml(const EmgTorqueModel& m, const std::vector<std::string>& header) {
  std::ostringstream o;
  for (const std::string& h : header) o << "# " << h << "\n";
  o << "# EMG-driven joint moment per joint (N m, along the coordinate: hip flexion +, knee extension +):\n"
       "#   tau = sum (alpha + alpha_q q) a(e(t - delay)) + beta q + gamma qd + offset + passive_scale M_P(q)\n"
       "#   a(u) = (exp(A u) - 1) / (exp(A) - 1) (Lloyd & Besier 2003; A = 0: a = u), M_P: Riener & Edrich 1999\n"
       "#   e filtered by the muscle twitch (critically damped, time constant tau; 0: none) before a(u)\n"
       "# se: standard error (residual autocorrelation taken into account); alpha per unit envelope.\n";
  o << "model: emg_torque_hj15\n";
  o << "activation: {A_shape: " << NumberText(m.spec.a_shape, 10) << ", se: " << NumberText(m.spec.a_shape_se, 4)
    << ", unit: \"1\"}\n";
  o << "twitch: {tau: " << NumberText(m.spec.twitch, 10) << ", se: " << NumberText(m.spec.twitch_se, 4) << ", unit: s}\n";
  o << "delays:";
  if (m.spec.delay_s.empty() && m.spec.common_delay == 0) o << " {}";
  o << "\n";
  if (m.spec.common_delay != 0)
    o << "  common: {value: " << NumberText(m.spec.common_delay, 10) << ", se: " << NumberText(m.spec.common_delay_se, 4)
      << ", unit: s}\n";
  for (const auto& d : m.spec.delay_s)
    o << "  " << MuscleName(d.first) << ": {value: " << NumberText(d.second, 10) << ", se: "
      << NumberText(m.spec.delay_se.count(d.first) ? m.spec.delay_se.at(d.first) : 0.0, 4) << ", unit: s}\n";
  auto yn = [](bool b) { return b ? "true" : "false"; };
  o << "structure:\n  moment_arm: {hip: " << yn(m.spec.moment_arm[0]) << ", knee: " << yn(m.spec.moment_arm[1])
    << "}\n  passive: {hip: " << yn(m.spec.passive[0]) << ", knee: " << yn(m.spec.passive[1])
    << "}\n  gmax_proxy: " << yn(m.spec.gmax_proxy) << "\n  robust_fit: " << yn(m.spec.robust)
    << "\n  signed_alphas: " << yn(m.spec.signed_alphas) << "\n  pooled: [";
  for (size_t i = 0; i < m.spec.pooled.size(); ++i) o << (i ? ", " : "") << MuscleName(m.spec.pooled[i]);
  o << "]\n";
  o << "missing_channels: [";
  for (size_t i = 0; i < m.missing.size(); ++i) o << (i ? ", " : "") << m.missing[i];
  o << "]\nautocorrelation_rows: " << NumberText(m.autocorr_rows, 6) << "\n";
  auto terms = [&](const char* key, const std::vector<EmgTerm>& list) {
    o << key << ":\n";
    for (int j = 0; j < 2; ++j) {
      o << "  " << kJointName[j] << ":\n";
      for (const EmgTerm& t : list) {
        if (t.joint != j) continue;
        o << "    - {term: " << t.Kind();
        if (!t.channel.empty())
          o << ", channel: " << t.channel << ", muscle: " << MuscleName(t.muscle)
            << (t.proxy ? ", proxy_for: GMAX" : "")
            << ", expected_sign: " << t.ExpectedSign() << (t.held ? ", held_at_zero: true" : "");
        o << ", value: " << NumberText(t.value, 10) << ", se: " << NumberText(t.se, 4) << ", unit: \"" << t.Unit()
          << "\"}\n";
      }
    }
  };
  terms("parameters", m.terms);
  if (!m.papers_terms.empty()) {
    o << "# The papers' form (HJ15 eq. 26, alphas free of sign, every sample): it predicts a joint of another\n"
         "# gait (more than half the samples outside calibration_range there).\n";
    terms("papers_form", m.papers_terms);
  }
  if (!m.range.empty()) {
    // 17 significant digits: the ends read back exactly (a sample at the end is inside).
    auto pair = [](double a, double b) { return "[" + NumberText(a, 17) + ", " + NumberText(b, 17) + "]"; };
    o << "calibration_range:\n  envelope: {";
    for (size_t c = 0; c < m.range.channels.size(); ++c)
      o << (c ? ", " : "") << m.range.channels[c] << ": " << pair(m.range.e_lo[c], m.range.e_hi[c]);
    o << "}\n  angle: {hip: " << pair(m.range.q_lo[0], m.range.q_hi[0]) << ", knee: " << pair(m.range.q_lo[1], m.range.q_hi[1])
      << ", unit: rad}\n  velocity: {hip: " << pair(m.range.qd_lo[0], m.range.qd_hi[0])
      << ", knee: " << pair(m.range.qd_lo[1], m.range.qd_hi[1]) << ", unit: rad/s}\n";
  }
  if (m.msk.present) o << EmgMskYaml(m);
  o << "fit:\n  validation: \"" << (m.folds_are_recordings ? "each recording left out in turn" : "contiguous blocks left out in turn")
    << "\"\n  folds: " << m.sse_fold.size() << "\n";
  for (int j = 0; j < 2; ++j) {
    const EmgJointFigures& F = m.figures[j];
    o << "  " << kJointName[j] << ": {r2_cv: " << NumberText(F.r2_cv, 4) << ", rms_cv: " << NumberText(F.rms_cv, 4)
      << ", r2_fit: " << NumberText(F.r2_fit, 4) << ", r2_heldout: " << NumberText(F.r2_heldout, 4)
      << ", rms_heldout: " << NumberText(F.rms_heldout, 4) << ", r2_heldout_within_6mad: "
      << NumberText(F.r2_heldout_trim, 4) << ", rms_heldout_within_6mad: " << NumberText(F.rms_heldout_trim, 4)
      << ", heldout_samples: " << F.heldout << "}\n";
  }
  return o.str();
}

namespace {
// The term lists of `block` (parameters, papers_form): hip: [...] and knee: [...].
std::vector<EmgTerm> ReadEmgTerms(const YamlContext& c, const YAML::Node& p, const std::string& block);
}  // namespace

EmgTorqueModel ReadEmgModel(const std::string& path) {
  const YamlContext c{path};
  const YAML::Node root = ParseYaml(ReadYamlText(path, "EMG model"), path);
  YamlCheckKeys(c, root, "",
                {"model", "activation", "twitch", "delays", "structure", "missing_channels", "autocorrelation_rows",
                 "parameters", "calibration_range", "fit", "forms", "musculoskeletal", "papers_form"});
  if (!root["model"] || !root["model"].IsScalar() || root["model"].as<std::string>() != "emg_torque_hj15")
    c.Fail("model", "expected 'emg_torque_hj15' (a file written by exotwin emg-fit)" + YamlLine(root["model"]));
  EmgTorqueModel m;
  if (const YAML::Node a = root["activation"]) m.spec.a_shape = YamlNumber(c, a["A_shape"], "activation.A_shape", -10, 10, "");
  if (const YAML::Node tw = root["twitch"]) m.spec.twitch = YamlNumber(c, tw["tau"], "twitch.tau", 0, 1, "s");
  if (const YAML::Node d = root["delays"]) {
    if (!d.IsMap()) c.Fail("delays", "expected a mapping of muscles to delays" + YamlLine(d));
    for (const auto& kv : d) {
      Muscle mu;
      const std::string k = kv.first.as<std::string>();
      const double v = YamlNumber(c, kv.second["value"], "delays." + k + ".value", -1, 1, "s");
      if (k == "common") m.spec.common_delay = v;
      else if (MuscleByName(k, &mu)) m.spec.delay_s[mu] = v;
      else c.Fail("delays." + k, "expected common, GMAX, VM, RF, ST or GAS" + YamlLine(kv.first));
    }
  }
  if (const YAML::Node s = root["structure"]) {
    auto flag = [&](const YAML::Node& n, const std::string& key) {
      if (!n || !n.IsScalar() || (n.as<std::string>() != "true" && n.as<std::string>() != "false"))
        c.Fail(key, "expected true or false" + YamlLine(n));
      return n.as<std::string>() == "true";
    };
    for (int j = 0; j < 2; ++j) {
      m.spec.moment_arm[j] = flag(s["moment_arm"][kJointName[j]], std::string("structure.moment_arm.") + kJointName[j]);
      m.spec.passive[j] = flag(s["passive"][kJointName[j]], std::string("structure.passive.") + kJointName[j]);
    }
    m.spec.gmax_proxy = flag(s["gmax_proxy"], "structure.gmax_proxy");
    m.spec.robust = flag(s["robust_fit"], "structure.robust_fit");
    if (s["signed_alphas"]) m.spec.signed_alphas = flag(s["signed_alphas"], "structure.signed_alphas");
    if (const YAML::Node pl = s["pooled"]) {
      if (!pl.IsSequence()) c.Fail("structure.pooled", "expected a list of muscles" + YamlLine(pl));
      for (const auto& x : pl) {
        Muscle mu;
        if (!MuscleByName(x.as<std::string>(), &mu)) c.Fail("structure.pooled", "expected GMAX, VM, RF, ST or GAS" + YamlLine(x));
        m.spec.pooled.push_back(mu);
      }
    }
  }
  if (const YAML::Node g = root["calibration_range"]) {
    auto pair = [&](const YAML::Node& n, const std::string& key, double* lo, double* hi) {
      if (!n || !n.IsSequence() || n.size() != 2) c.Fail(key, "expected [low, high]" + YamlLine(n));
      *lo = YamlNumber(c, n[0], key + "[0]", -1e6, 1e6, ""), *hi = YamlNumber(c, n[1], key + "[1]", *lo, 1e6, "");
    };
    if (!g["envelope"] || !g["envelope"].IsMap()) c.Fail("calibration_range.envelope", "expected channel: [low, high]" + YamlLine(g));
    for (const auto& kv : g["envelope"]) {
      const std::string ch = kv.first.as<std::string>();
      double lo, hi;
      pair(kv.second, "calibration_range.envelope." + ch, &lo, &hi);
      m.range.channels.push_back(ch), m.range.e_lo.push_back(lo), m.range.e_hi.push_back(hi);
    }
    for (int j = 0; j < 2; ++j) {
      pair(g["angle"][kJointName[j]], std::string("calibration_range.angle.") + kJointName[j], &m.range.q_lo[j], &m.range.q_hi[j]);
      pair(g["velocity"][kJointName[j]], std::string("calibration_range.velocity.") + kJointName[j], &m.range.qd_lo[j],
           &m.range.qd_hi[j]);
      m.spec.q_lo[j] = m.range.q_lo[j], m.spec.q_hi[j] = m.range.q_hi[j];
    }
    m.spec.bounded = true;
  }
  if (const YAML::Node mc = root["missing_channels"])
    for (const auto& x : mc) m.missing.push_back(x.as<std::string>());
  ReadEmgMsk(c, root, &m);
  const YAML::Node p = root["parameters"];
  if (!p || !p.IsMap()) c.Fail("parameters", "expected hip: and knee: lists of parameters");
  m.terms = ReadEmgTerms(c, p, "parameters");
  if (const YAML::Node pf = root["papers_form"]) {
    if (!pf.IsMap()) c.Fail("papers_form", "expected hip: and knee: lists of parameters" + YamlLine(pf));
    m.papers_terms = ReadEmgTerms(c, pf, "papers_form");
    for (const EmgTerm& t : m.papers_terms)
      if (t.kind == TermKind::kAlphaQ || t.kind == TermKind::kPassive || t.channel.find('+') != std::string::npos)
        c.Fail("papers_form." + std::string(kJointName[t.joint]), "expected the papers' terms only (alpha of one channel, "
               "beta, gamma, offset), found " + t.Name());
  }
  return m;
}

namespace {

std::vector<EmgTerm> ReadEmgTerms(const YamlContext& c, const YAML::Node& p, const std::string& block) {
  std::vector<EmgTerm> terms;
  const std::map<std::string, TermKind> kinds = {{"alpha", TermKind::kAlpha},   {"alpha_q", TermKind::kAlphaQ},
                                                 {"beta", TermKind::kBeta},     {"gamma", TermKind::kGamma},
                                                 {"offset", TermKind::kOffset}, {"passive_scale", TermKind::kPassive}};
  for (int j = 0; j < 2; ++j) {
    const YAML::Node list = p[kJointName[j]];
    const std::string key = block + "." + kJointName[j];
    if (!list || !list.IsSequence()) c.Fail(key, "expected a list of parameters" + YamlLine(list));
    for (size_t i = 0; i < list.size(); ++i) {
      const YAML::Node e = list[i];
      const std::string ek = key + "[" + std::to_string(i) + "]";
      EmgTerm t;
      t.joint = j;
      if (!e["term"] || !kinds.count(e["term"].as<std::string>()))
        c.Fail(ek + ".term", "expected alpha, alpha_q, beta, gamma, offset or passive_scale" + YamlLine(e));
      t.kind = kinds.at(e["term"].as<std::string>());
      if (t.kind == TermKind::kAlpha || t.kind == TermKind::kAlphaQ) {
        if (!e["channel"] || !e["muscle"] || !MuscleByName(e["muscle"].as<std::string>(), &t.muscle))
          c.Fail(ek, "expected channel: and muscle: (GMAX, VM, RF, ST, GAS)" + YamlLine(e));
        t.channel = e["channel"].as<std::string>();
        t.proxy = static_cast<bool>(e["proxy_for"]);
        if (e["held_at_zero"]) {
          if (!e["held_at_zero"].IsScalar() || e["held_at_zero"].as<std::string>() != "true")
            c.Fail(ek + ".held_at_zero", "expected true (absent when the alpha is fitted)" + YamlLine(e["held_at_zero"]));
          t.held = true;
        }
      }
      t.value = YamlNumber(c, e["value"], ek + ".value", -1e6, 1e6, t.Unit());
      if (e["se"]) t.se = YamlNumber(c, e["se"], ek + ".se", 0, 1e12, t.Unit());
      terms.push_back(t);
    }
  }
  return terms;
}

}  // namespace

}  // namespace exotwin
