#include "diagnosis/diagnose.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "diagnosis/diagnose_columns.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/term_search.h"
#include "diagnosis/diagnose_select.h"
#include "diagnosis/diagnose_unexplained.h"
#include "diagnosis/effects.h"
#include "diagnosis/generate.h"
#include "diagnosis/motion_fit.h"
#include "diagnosis/fit_families.h"
#include "formats/number_text.h"
#include "diagnosis/predict.h"
#include "dsp/statistics.h"
#include "core/error.h"
#include "core/heap_policy.h"
#include "core/parallel_for.h"
#include "dsp/butterworth.h"
#include "model/leg_dynamics.h"
#include "sim/plant.h"

namespace exotwin {

int DiagnoseThreads(const DiagnoseOptions& opt) {
  if (opt.threads > 0) return opt.threads;
  return MachineCores();
}

const char* DiagnoseFitName(DiagnoseFit fit) { return fit == DiagnoseFit::kMotion ? "motion" : "torque"; }

DiagnoseFit ParseDiagnoseFit(const std::string& text, const std::string& where) {
  if (text == "torque") return DiagnoseFit::kTorque;
  if (text == "motion") return DiagnoseFit::kMotion;
  throw InputError(where + ": '" + text + "', expected torque or motion");
}

bool DiagnoseReadsColumn(const std::string& name, DiagnoseFit fit) {
  if (name.rfind("qd_", 0) == 0 || name.rfind("qdd_", 0) == 0 || name.rfind("emg_", 0) == 0) return IsMeasuredColumn(name);
  return fit == DiagnoseFit::kMotion && IsMeasuredColumn(name) && name.rfind("cmd_", 0) == 0;
}
namespace {

using torque_fit::Rec;
using torque_fit::ExtendAndRefine;
using torque_fit::PrepareRecord;
using torque_fit::RangeEdge;
using torque_fit::RefineRows;
using torque_fit::UseSecantColumns;
using torque_fit::SearchTerms;
using torque_fit::BlackBoxShareOfResidual;
using torque_fit::CeilingLeavesStructure;
using torque_fit::TermSearchResult;

// Autocorrelation length (in rows) of a residual of 2m rows (hip block, knee block): the longer.
double AutocorrLength(const Eigen::VectorXd& e, size_t m) {
  return std::max(AutocorrelationLength(e.data(), m), AutocorrelationLength(e.data() + m, m));
}

}  // namespace

namespace torque_fit {

void RigidTorque(const LegParams& params, const Kinematics& kin, int threads, std::vector<double> tau_R[2]) {
  const size_t n = kin.t.size();
  for (int j = 0; j < 2; ++j) tau_R[j].resize(n);
  ParallelForRanges(n, threads, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector2d tau = ActuatorTorque(params, {kin.q[0][i], kin.q[1][i]}, {kin.qd[0][i], kin.qd[1][i]},
                                                 {kin.qdd[0][i], kin.qdd[1][i]});
      tau_R[0][i] = tau[0], tau_R[1][i] = tau[1];
    }
  });
}

}  // namespace torque_fit

// Held-out scores from the sums of squares before / after over `count` samples.
JointScore ScoreOf(double sse_before, double sse_after, double count) {
  return {std::sqrt(sse_before / count), std::sqrt(sse_after / count),
          sse_before > 0 ? 100 * (1 - std::sqrt(sse_after / sse_before)) : 0};
}

namespace {

// Records of one device: the same columns the analysis reads, and sample rates within a factor 5.
void CheckSameDevice(const std::vector<const MeasuredData*>& records) {
  auto known = [](const MeasuredData& d) {
    std::set<std::string> s;
    for (const auto& n : d.table.names)
      if (n.rfind("emg_", 0) == 0 || n.rfind("qd_", 0) == 0 || n.rfind("qdd_", 0) == 0) s.insert(n);
    return s;
  };
  const MeasuredData& a = *records[0];
  const std::set<std::string> ka = known(a);
  const double dta = MedianStep(a.t());
  for (size_t i = 1; i < records.size(); ++i) {
    const MeasuredData& b = *records[i];
    if (known(b) != ka) {
      std::string sa, sb;
      for (const auto& n : ka) sa += " " + n;
      for (const auto& n : known(b)) sb += " " + n;
      throw InputError(b.source + ": columns (emg_*, qd_*, qdd_*:" + (sb.empty() ? " none" : sb) +
                       ") differ from " + a.source + "'s (" + (sa.empty() ? " none" : sa) +
                       "), expected records of one device with the same columns");
    }
    const double r = MedianStep(b.t()) / dta;
    if (!(r < 5 && r > 0.2))
      throw InputError(b.source + ": median time step " + NumberText(MedianStep(b.t())) + " s against " +
                       NumberText(dta) + " s in " + a.source +
                       ", expected records of one device in the same time unit (s)");
  }
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
  k.t_start = kin.t_start;
  return k;
}

// kin cut to its samples [a, b) in place (what Slice(kin, a, b) holds, without a copy).
void TrimTo(Kinematics* kin, size_t a, size_t b) {
  auto cut = [&](std::vector<double>& v) {
    v.erase(v.begin() + static_cast<long>(b), v.end());
    v.erase(v.begin(), v.begin() + static_cast<long>(a));
  };
  cut(kin->t);
  for (int j = 0; j < 2; ++j) cut(kin->q[j]), cut(kin->qd[j]), cut(kin->qdd[j]);
  for (auto& ch : kin->emg) cut(ch.second);
  kin->resampled = false;  // as Slice
}


// Stage 0: the records and options are fit for a diagnosis (>= 200 samples each, holdout 0.1..0.5,
// 0..6 effects, one device); throws InputError otherwise.
void CheckInputs(const std::vector<const MeasuredData*>& records, const DiagnoseOptions& opt) {
  if (records.empty()) throw InputError("diagnose: expected at least one measured record");
  for (const MeasuredData* d : records)
    if (d->size() < 200)
      throw InputError(d->source + ": " + std::to_string(d->size()) +
                       " samples, expected at least 200 for a diagnosis (fit and held-out parts)");
  if (!(opt.holdout_fraction >= 0.1 && opt.holdout_fraction <= 0.5))
    throw InputError("holdout fraction: expected 0.1 .. 0.5");
  if (!(opt.max_effects >= 0 && opt.max_effects <= 6)) throw InputError("max effects: expected 0 .. 6");
  CheckSameDevice(records);
}

// Stage 1: the derivative cutoff (Hz), given by the options (> 0) or chosen from the data for
// parallel filtering (derivative_cutoff.h, CutoffUse::kParallel).
CutoffChoice ResolveCutoff(const LegParams& params, const std::vector<const MeasuredData*>& records,
                           const DiagnoseOptions& opt) {
  if (opt.cutoff_hz > 0) {
    CutoffChoice c;
    c.hz = opt.cutoff_hz;
    c.why = "given (--cutoff " + NumberText(opt.cutoff_hz) + ")";
    return c;
  }
  return ChooseCutoff(records, params.L1, params.g, CutoffUse::kParallel, DiagnoseThreads(opt));
}

}  // namespace

namespace torque_fit {

void PrepareRecord(const LegParams& params, const MeasuredData& data, MeasuredData* owned,
                   const CutoffChoice& cutoff, double holdout_fraction, int threads, Rec* out) {
  Rec& rc = *out;
  rc.source = data.source;
  rc.samples = data.size();
  // Parallel filtering (as in robot identification practice): the residual is low-passed at the
  // chosen cutoff fc, the angles differentiated at DerivativeCutoffHz(fc), flat where fc passes,
  // so that measured and predicted torque see one and the same filter.
  const double hz = cutoff.from_columns ? 20.0 : DerivativeCutoffHz(cutoff.hz, 1.0 / MedianStep(data.t()));
  const std::vector<double>* meas[2] = {&data.tau_hip(), &data.tau_knee()};
  if (owned) {
    for (int j = 0; j < 2; ++j) {
      rc.taken[j] = std::move(owned->column_at(j == 0 ? kColTauHip : kColTauKnee));
      meas[j] = &rc.taken[j];
    }
    rc.kin = DeriveKinematics(std::move(*owned), hz);
  } else {
    rc.kin = DeriveKinematics(data, hz);
  }
  const bool filtered = rc.kin.derivative_source != "measured columns";
  rc.hz = filtered ? cutoff.hz : 0.0;
  // The zero-phase filters' start and end transients (about 0.5 s) are not data: trim.
  const std::vector<double>& t = rc.kin.t;
  const double T = t.back() - t.front();
  const double edge = std::min(0.5, 0.05 * T);
  const size_t a = static_cast<size_t>(std::lower_bound(t.begin(), t.end(), t.front() + edge) - t.begin());
  const size_t b = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), t.back() - edge) - t.begin());
  TrimTo(&rc.kin, a, b);
  if (filtered) rc.low.emplace(rc.kin.t, rc.hz, rc.source);
  for (int j = 0; j < 2; ++j) rc.raw[j] = meas[j]->data() + a;
  const Kinematics& kin = rc.kin;
  const double t_split = kin.t.front() + (1 - holdout_fraction) * (kin.t.back() - kin.t.front());
  rc.split = static_cast<size_t>(std::lower_bound(kin.t.begin(), kin.t.end(), t_split) - kin.t.begin());
  // The twin: HJ15 eq. 5-7 + P(q) + the model's own effects, which equals predict's MuJoCo inverse
  // dynamics to round-off (tests/integration) at a tenth of the cost; the extended twin's held-out
  // run (ScoreExtendedTwin) is predict itself.
  torque_fit::RigidTorque(params, kin, threads, rc.tau_R);
  if (params.effects.empty()) {
    ApplyEffects(params, kin, rc.tau_R, rc.tau_S);  // leaves rc.tau_R as it is
  } else {
    std::vector<double> rigid[2] = {rc.tau_R[0], rc.tau_R[1]};
    ApplyEffects(params, kin, rigid, rc.tau_S);  // rc.tau_R stays the rigid torque
  }
  rc.Residuals(rc.resid);
}

}  // namespace torque_fit

namespace {

// Stage 3c: the measured torque filtered as the residual, into rc.meas (after the candidate columns,
// whose temporaries are gone by then: a long record's peak memory).
void FilterMeasured(std::vector<Rec>* recs) {
  for (Rec& rc : *recs) {
    for (int j = 0; j < 2; ++j) rc.meas[j].assign(rc.raw[j], rc.raw[j] + rc.n());
    rc.FilterBoth(rc.meas);
  }
}

// Stage 2b: white noise per joint (N m, >= 1e-6) from the first differences of the residuals,
// pooled over records, into noise[]; the row weights 1/noise into w[].
void NoiseAndWeights(const std::vector<Rec>& recs, double noise[2], double w[2]) {
  for (int j = 0; j < 2; ++j) {
    double s = 0, cnt = 0;
    for (const Rec& rc : recs)
      for (size_t i = 1; i < rc.n(); ++i) s += std::pow(rc.resid[j][i] - rc.resid[j][i - 1], 2), cnt += 1;
    noise[j] = std::max(1e-6, std::sqrt(s / (2.0 * std::max(cnt, 1.0))));
    w[j] = 1.0 / noise[j];
  }
}

// Residual of every bank after the kitchen-sink fit: all candidate columns at once, least squares
// pooled over the banks (lightly regularized).
std::vector<Eigen::VectorXd> KitchenSinkResiduals(const std::vector<ColumnBank>& banks) {
  const Eigen::Index C = banks[0].X.cols();
  Eigen::MatrixXd Gr = Eigen::MatrixXd::Zero(C, C);
  Eigen::VectorXd br = Eigen::VectorXd::Zero(C);
  for (const ColumnBank& b : banks) {
    Gr.selfadjointView<Eigen::Lower>().rankUpdate(b.X.transpose());
    br += b.X.transpose() * b.r;
  }
  Gr = Gr.selfadjointView<Eigen::Lower>();
  Gr.diagonal() += 1e-9 * Gr.diagonal().cwiseMax(1e-300);
  const Eigen::VectorXd c = Gr.ldlt().solve(br);
  std::vector<Eigen::VectorXd> out;
  for (const ColumnBank& b : banks) out.push_back(b.r - b.X * c);
  return out;
}


// Stage 3: the candidate columns of every record (the same columns in each bank, rows weighted by
// w), with the ripple candidates' frequency searched.
std::vector<ColumnBank> CandidateColumns(const LegParams& params, std::vector<Rec>& recs,
                                         const double w[2], const DiagnoseOptions& opt) {
  const size_t R = recs.size();
  std::vector<ColumnBank> banks;
  std::vector<const Kinematics*> kins;
  for (Rec& rc : recs) {  // BuildColumns releases rc.resid (a long record's memory)
    banks.push_back(BuildColumns(params, rc.kin, rc.tau_S, rc.resid, w, rc.split,
                                 std::max<size_t>(2000, opt.max_fit_rows / R), rc.FilterFn(), DiagnoseThreads(opt)));
    kins.push_back(&rc.kin);
  }
  ReturnFreedMemory();  // the columns' record-long temporaries, before the ripple search lays out its own
  std::vector<Eigen::VectorXd> raw;
  const std::vector<Eigen::VectorXd> e = KitchenSinkResiduals(banks);
  for (const ColumnBank& b : banks) raw.push_back(b.r);
  // Ripple frequency searched on what the other candidates leave and on the raw residual (a slow
  // ripple, ~1 cycle over the range, is otherwise absorbed by the stiffness/gravity columns).
  AddSearchedCandidates(banks, kins, e);
  AddSearchedCandidates(banks, kins, raw);
  return banks;
}

// Stage 3b (one-joint device): only the candidates of joint j stay (the others' columns are left unused).
void KeepJointCandidates(int j, std::vector<ColumnBank>* banks) {
  for (ColumnBank& b : *banks)
    b.candidates.erase(std::remove_if(b.candidates.begin(), b.candidates.end(),
                                      [j](const Candidate& c) { return c.joint != j; }),
                       b.candidates.end());
}

// Stage 3c: the pooled Gram matrices of the banks, the measured torque's scale on the held-out rows
// (materiality), and the effective sample size from the autocorrelation length (rows, *tau_eff) of
// what no candidate explains.
Grams PooledGrams(const std::vector<Rec>& recs, const std::vector<ColumnBank>& banks, const double w[2],
                  double* tau_eff) {
  Grams g = MakeGrams(banks);
  for (size_t r = 0; r < recs.size(); ++r)
    for (size_t k = 0; k < banks[r].sample.size(); ++k)
      if (!banks[r].train[k])
        for (int j = 0; j < 2; ++j) g.tt_te[j] += std::pow(w[j] * recs[r].meas[j][banks[r].sample[k]], 2);
  // Autocorrelation length of what no candidate explains: kitchen sink incl. ripple.
  const std::vector<Eigen::VectorXd> e = KitchenSinkResiduals(banks);
  *tau_eff = 1;
  for (size_t r = 0; r < recs.size(); ++r)
    *tau_eff = std::max(*tau_eff, AutocorrLength(e[r], banks[r].sample.size()));
  g.n_eff = g.n_tr / *tau_eff;
  return g;
}

// Stage 4: the physical scale of the records (diagnose_select.h ScaleOf), of their kinematics and
// the measured torque filtered alike.
PhysicalScale ScaleOf(const LegParams& params, const std::vector<Rec>& recs) {
  std::vector<ScaleRecord> in;
  for (const Rec& rc : recs) in.push_back({&rc.kin, {&rc.meas[0], &rc.meas[1]}});
  return exotwin::ScaleOf(params, in);
}

// Stage 4b: the report's candidate table into D->scores (the 12 best single candidates by BIC, then
// the chosen set), single fits outside their physical range into D->implausible, candidates whose
// range's edge would not be significant into D->not_identifiable, and nearly
// collinear candidate pairs (|cos| > 0.95 of their first columns, train rows) into D->collinear.
void ScoreCandidates(const ColumnBank& bank, const Grams& g, const PhysicalScale& scale, const Fit& f0,
                     const std::vector<int>& chosen, const Fit& chosen_fit, Diagnosis* D) {
  auto gain = [&](const Fit& f) { return f0.sse_te > 0 ? 1 - f.sse_te / f0.sse_te : 0.0; };
  std::vector<std::pair<double, size_t>> order;
  std::vector<Fit> singles;
  for (size_t c = 0; c < bank.candidates.size(); ++c) {
    singles.push_back(FitCols(g, bank.candidates[c].cols));
    order.push_back({singles.back().ok ? singles.back().bic : 1e300, c});
  }
  std::sort(order.begin(), order.end());
  for (size_t i = 0; i < order.size() && i < 12; ++i) {
    const Fit& f = singles[order[i].second];
    const Candidate& c = bank.candidates[order[i].second];
    D->scores.push_back({c.Label(), f.ok ? f.bic - f0.bic : 0, 100 * gain(f),
                         std::find(chosen.begin(), chosen.end(), static_cast<int>(order[i].second)) != chosen.end()});
    if (!f.ok || !(f.bic < f0.bic - kBicMargin)) continue;
    const DiagnosedEffect e = ToEffect(c, f);
    std::string why;
    if (!Plausible(e, scale, &why))
      D->implausible.push_back(c.Label() + " = " + NumberText(e.effect.value) + " " + e.effect.unit + ": " + why);
  }
  for (size_t c = 0; c < bank.candidates.size(); ++c) {
    const Candidate& cand = bank.candidates[c];
    const double edge = RangeEdge(cand, scale);
    if (!(edge > 0)) continue;
    const double se = singles[c].ok ? SeOf(singles[c], cand.cols[0]) : INFINITY;
    if (edge < kMinT * se)
      D->not_identifiable.push_back(cand.Label() + ": standard error " + NumberText(se, 3) +
                                    " against a physical range up to " + NumberText(edge, 3) +
                                    ": not identifiable from these records, not fitted");
  }
  if (!chosen.empty()) {
    std::string label;
    for (int c : chosen) label += (label.empty() ? "" : " + ") + bank.candidates[c].Label();
    D->scores.push_back({label, chosen_fit.bic - f0.bic, 100 * gain(chosen_fit), true});
  }
  for (size_t a = 0; a < bank.candidates.size(); ++a)
    for (size_t b = a + 1; b < bank.candidates.size(); ++b) {
      const int ca = bank.candidates[a].cols[0], cb = bank.candidates[b].cols[0];
      if (ca == cb) continue;
      const double r = g.Gtr(ca, cb) / std::sqrt(g.Gtr(ca, ca) * g.Gtr(cb, cb) + 1e-300);
      if (std::abs(r) > 0.95)
        D->collinear.push_back(bank.candidates[a].Label() + " ~ " + bank.candidates[b].Label() +
                               " (|cos| = " + std::to_string(std::abs(r)).substr(0, 5) + ")");
    }
}

// Stage 5b: each named effect's aliases (DiagnosedEffect::aliases). With the other named effects
// (rest) fitted alongside, the effect lowers the fit rows' weighted error by drop = sse(rest) -
// sse(chosen). A set A of candidates (one, or two neither of which qualifies alone) is an alias when,
// with A fitted in its place, the effect would add at most kAliasLeft of that drop: sse(rest + A) -
// sse(rest + A + effect) <= kAliasLeft drop, i.e. its column lies in the span of A's (and the
// rest's) to within that share. A then reaches at least 1 - kAliasLeft of the drop itself (more is
// possible: a pair has a parameter more; whether that pays is the selection's judgement). Listed in
// range first, singles before pairs, then by reach. Fits on the train Grams only (no leave-one-out):
// a few thousand small solves per named effect.
void FindAliases(const ColumnBank& bank, const Grams& g, const PhysicalScale& scale, const std::vector<int>& chosen,
                 const Fit& chosen_fit, Diagnosis* D) {
  const int C = static_cast<int>(bank.candidates.size());
  for (size_t k = 0; k < chosen.size(); ++k) {
    std::vector<int> rest = chosen;
    rest.erase(rest.begin() + static_cast<long>(k));
    const Fit f_rest = FitCols(g, ColumnsOf(bank, rest), false);
    const double drop = f_rest.sse_tr - chosen_fit.sse_tr;
    if (!f_rest.ok || !(drop > 0)) continue;
    std::vector<EffectAlias> found;
    // Whether `alias` (candidate indices) is an alias; if so, its values and scores into *a.
    auto IsAlias = [&](const std::vector<int>& alias, EffectAlias* a) {
      std::vector<int> set = rest;
      set.insert(set.end(), alias.begin(), alias.end());
      const Fit f = FitCols(g, ColumnsOf(bank, set), false);
      if (!f.ok) return false;
      set.push_back(chosen[k]);
      const Fit with = FitCols(g, ColumnsOf(bank, set), false);
      // Singular with the effect added: its column is in the alias's span (exactly).
      const double left = with.ok ? std::max(0.0, f.sse_tr - with.sse_tr) / drop : 0.0;
      if (left > kAliasLeft) return false;
      a->reach_pct = 100 * (f_rest.sse_tr - f.sse_tr) / drop;
      a->left_pct = 100 * left;
      for (int c : alias) {
        const DiagnosedEffect e = ToEffect(bank.candidates[static_cast<size_t>(c)], f);
        a->plausible = a->plausible && Plausible(e, scale);
        a->effects.push_back(e.effect);
      }
      return true;
    };
    auto Named = [&](int c) { return std::find(chosen.begin(), chosen.end(), c) != chosen.end(); };
    std::vector<bool> alone(static_cast<size_t>(C), false);
    for (int c = 0; c < C; ++c) {
      EffectAlias a;
      if (!Named(c) && IsAlias({c}, &a)) alone[static_cast<size_t>(c)] = true, found.push_back(a);
    }
    for (int c1 = 0; c1 < C; ++c1)
      for (int c2 = c1 + 1; c2 < C; ++c2) {
        if (Named(c1) || Named(c2) || alone[static_cast<size_t>(c1)] || alone[static_cast<size_t>(c2)]) continue;
        EffectAlias a;
        if (IsAlias({c1, c2}, &a)) found.push_back(a);
      }
    std::stable_sort(found.begin(), found.end(), [](const EffectAlias& a, const EffectAlias& b) {
      if (a.plausible != b.plausible) return a.plausible;
      if (a.effects.size() != b.effects.size()) return a.effects.size() < b.effects.size();
      return a.reach_pct > b.reach_pct;
    });
    if (found.size() > kMaxAliases) found.resize(kMaxAliases);
    D->effects[k].aliases = std::move(found);
  }
}

// Stage 5c's state for stage 6c: the black box's rows, whether the residual tests alone decided the
// search (the table's ceiling then waits for the final model's: one fit), the search's result.
struct Stage5c {
  torque_fit::CeilingRows rows;
  bool tests_decide = true;
  TermSearchResult searched;
};

// Stage 5c: the residual tests of the table's best model (D->table_model) and, where they leave a joint
// complete, its ceiling, which can start the search there (CeilingLeavesStructure); where it is
// incomplete, the search for terms beyond the table at those joints (term_search.h).
Stage5c AssessAndSearch(const LegParams& params, const std::vector<Rec>& recs, const double w[2],
                        const std::vector<ColumnBank>& banks, const PhysicalScale& scale, const DiagnoseOptions& opt,
                        Diagnosis* D_out) {
  Stage5c st;
  Diagnosis& D = *D_out;
  std::array<JointCompleteness, 2> on_fit_rows;
  D.table_model = torque_fit::TestModel(params, D.extended, recs, opt, &st.rows, &on_fit_rows);
  bool incomplete[2];
  // The table's ceiling before the search where the residual tests leave a joint complete (it can
  // start the search there); else it waits for the final model's, one black box fit for both.
  const int j0 = params.one_joint ? 1 : 0;
  bool& tests_decide = st.tests_decide;
  if (opt.search_terms) {
    for (int j = j0; j < 2; ++j) tests_decide = tests_decide && (!D.table_model.completeness[j].complete || !on_fit_rows[j].complete);
  }
  if (!tests_decide) torque_fit::FitCeilings(st.rows, {&D.table_model}, opt);
  for (int j = 0; j < 2; ++j) {
    const JointCompleteness& held = D.table_model.completeness[j];
    const bool ceiling = !tests_decide && CeilingLeavesStructure(D.table_model.ceiling[j], held.floor);
    incomplete[j] = opt.search_terms && (!held.complete || !on_fit_rows[j].complete || ceiling);
    if (incomplete[j])
      D.term_search.push_back(std::string(j == 0 ? "hip" : "knee") + ": the table's best model is incomplete (" +
                              (!held.complete ? "residual tests on the held-out rows; " : "") +
                              (!on_fit_rows[j].complete ? "residual tests on the fit rows; " : "") +
                              (ceiling ? "the black box lowers its held-out error by " +
                                             NumberText(100 * BlackBoxShareOfResidual(D.table_model.ceiling[j]), 3) + " %; " : "") +
                              "searched)");
  }
  if (incomplete[0] || incomplete[1]) st.searched = SearchTerms(params, recs, w, banks, scale, incomplete, DiagnoseThreads(opt), &D);
  return st;
}

// Stage 6: the extended twin (predict with D->extended) on every record's held-out part: the scores
// per record and pooled (D->records, D->joints) and the first record's plot series; with several
// records, each whole record predicted by the effects fitted on the others (D->left_out).
void ScoreExtendedTwin(const LegParams& params, std::vector<Rec>& recs, const ColumnBank& bank,
                       const Grams& g, const std::vector<int>& chosen, const std::vector<double>& refine_ratio,
                       const std::vector<std::vector<Effect>>& searched_left_out, const DiagnoseOptions& opt,
                       Diagnosis* D_out) {
  Diagnosis& D = *D_out;
  const size_t R = recs.size();
  // The extended twin's inverse dynamics on DiagnoseThreads plants (PredictTorque's ranges), one for a
  // short record.
  size_t longest = 0;
  for (const Rec& rc : recs) longest = std::max(longest, rc.n());
  const size_t T = longest < kMinSamplesToSplit ? 1 : static_cast<size_t>(DiagnoseThreads(opt));
  std::vector<std::unique_ptr<Plant>> ext_plants;
  std::vector<Plant*> ext;
  for (size_t k = 0; k < T; ++k) {
    ext_plants.push_back(std::make_unique<Plant>(opt.mjcf.empty() ? ExowheelMjcfPath(D.extended.human.has_value()) : opt.mjcf));
    ext_plants.back()->SetParams(D.extended);
    ext.push_back(ext_plants.back().get());
  }
  double sb[2] = {0, 0}, sa[2] = {0, 0}, cnt = 0, lb[2] = {0, 0}, la[2] = {0, 0}, lcnt = 0;
  const std::vector<int> cols = ColumnsOf(bank, chosen);
  for (size_t r = 0; r < R; ++r) {
    Rec& rc = recs[r];
    const size_t n = rc.n();
    // The residual again (released by the candidate columns), then the twin's reading is done with.
    std::vector<double> resid[2];
    rc.Residuals(resid);
    for (int j = 0; j < 2; ++j) std::vector<double>().swap(rc.tau_S[j]);
    RecordScore rs;
    rs.source = rc.source;
    rs.samples = rc.samples;
    // The held-out run starts 1 s early so that its filters (EMG envelope, delay) have settled;
    // only the held-out samples are scored.
    const size_t warm = static_cast<size_t>(
        std::lower_bound(rc.kin.t.begin(), rc.kin.t.end(), rc.kin.t[rc.split] - 1.0) - rc.kin.t.begin());
    const Prediction held = PredictTorque(ext, Slice(rc.kin, warm, n));
    std::vector<double> held_error[2];
    for (int j = 0; j < 2; ++j) {
      held_error[j].resize(n - warm);
      for (size_t i = warm; i < n; ++i) held_error[j][i - warm] = rc.raw[j][i] - held.tau_S[j][i - warm];
    }
    rc.FilterBoth(held_error, warm);
    for (int j = 0; j < 2; ++j) {
      const std::vector<double>& ea = held_error[j];
      double b = 0, a = 0;
      for (size_t i = rc.split; i < n; ++i) {
        b += std::pow(resid[j][i], 2);
        a += std::pow(ea[i - warm], 2);
      }
      rs.split[j] = ScoreOf(b, a, static_cast<double>(std::max<size_t>(1, n - rc.split)));
      sb[j] += b, sa[j] += a;
      if (r == 0) {
        D.before[j].resize(n);
        for (size_t i = 0; i < n; ++i) D.before[j][i] = rc.meas[j][i] - resid[j][i];
        D.after[j].assign(n, std::nan(""));  // the extended twin is scored on the held-out part only
        for (size_t i = rc.split; i < n; ++i) D.after[j][i] = rc.meas[j][i] - ea[i - warm];
        D.measured[j] = std::move(rc.meas[j]);  // its last use (a long record's memory)
      }
      std::vector<double>().swap(rc.meas[j]);
    }
    cnt += static_cast<double>(n - rc.split);
    if (D.leave_one_out) {
      LegParams p = params;
      if (!searched_left_out.empty()) {  // the terms' search rewrote the model: its own refits
        if (searched_left_out[r].empty())
          throw InputError(rc.source + ": without this record the named effects and terms are not identifiable");
        p.effects.insert(p.effects.end(), searched_left_out[r].begin(), searched_left_out[r].end());
      } else {
        const Eigen::VectorXd x = cols.empty() ? Eigen::VectorXd() : FitLeavingOut(g, cols, r);
        if (!cols.empty() && x.size() == 0)
          throw InputError(rc.source + ": without this record the chosen effects are not identifiable");
        for (size_t k = 0; k < chosen.size(); ++k) {
          Effect e = ToEffect(bank.candidates[chosen[k]], x, cols).effect;
          e.value *= refine_ratio[k];
          p.effects.push_back(e);
        }
      }
      rs.left_out_effects = p.effects;
      Plant loo_plant(opt.mjcf.empty() ? ExowheelMjcfPath(p.human.has_value()) : opt.mjcf);
      loo_plant.SetParams(p);
      const Prediction whole = PredictTorque(loo_plant, rc.kin);
      std::vector<double> whole_error[2];
      for (int j = 0; j < 2; ++j) {
        whole_error[j].resize(n);
        for (size_t i = 0; i < n; ++i) whole_error[j][i] = rc.raw[j][i] - whole.tau_S[j][i];
      }
      rc.FilterBoth(whole_error);
      for (int j = 0; j < 2; ++j) {
        const std::vector<double>& ea = whole_error[j];
        double b = 0, a = 0;
        for (size_t i = 0; i < n; ++i) b += std::pow(resid[j][i], 2), a += std::pow(ea[i], 2);
        rs.left_out[j] = ScoreOf(b, a, static_cast<double>(n));
        lb[j] += b, la[j] += a;
      }
      lcnt += static_cast<double>(n);
    }
    D.records.push_back(rs);
  }
  for (int j = 0; j < 2; ++j) {
    D.joints[j] = ScoreOf(sb[j], sa[j], cnt);
    if (D.leave_one_out) D.left_out[j] = ScoreOf(lb[j], la[j], lcnt);
  }
}

// Stage 6b: the rigid and the extended twin simulated forward (replay.h) on every record's held-out
// part and, with several records, on every whole record with the effects fitted on the others
// (D->simulation, RecordScore::sim_*). Needs the records' kinematics and raw torque, D->extended and
// D->records[r].left_out_effects. The records' last stage: their measured torque, time and angles are
// taken into each replay series (not copied) and the time and angles given back.
void SimulateTwins(const LegParams& params, std::vector<Rec>& recs, const DiagnoseOptions& opt, Diagnosis* D_out) {
  Diagnosis& D = *D_out;
  SimulationScores& S = D.simulation;
  S.horizon_s = opt.replay_horizon_s;
  S.cutoff_hz = opt.replay_cutoff_hz;
  if (!opt.simulate) {
    S.note = "not simulated (DiagnoseOptions::simulate off)";
    return;
  }
  // A plant carrying `model`'s effects; false (and S.note) when it cannot carry them.
  auto Make = [&](const LegParams& model, const std::string& which, std::unique_ptr<Plant>* plant,
                  PlantEffects* fx) {
    try {
      *plant = MakeReplayPlant(model, which, opt.mjcf, fx);
    } catch (const InputError& e) {
      S.note = std::string("not simulated: ") + e.what();
      return false;
    }
    return true;
  };
  std::unique_ptr<Plant> rigid, ext;
  PlantEffects rigid_fx, ext_fx;
  if (!Make(params, "the model given", &rigid, &rigid_fx) || !Make(D.extended, "the extended twin", &ext, &ext_fx))
    return;
  ReplayScore sb, sa, lb, la;
  for (size_t r = 0; r < recs.size(); ++r) {
    Rec& rc = recs[r];
    RecordScore& rs = D.records[r];
    const size_t n = rc.n();
    const std::vector<double> tau_S[2] = {rc.TakeRaw(0), rc.TakeRaw(1)};
    // One series; its input re-formed for each twin's sensor effects (memory of long records). The
    // record's time and angles are moved into it, and back into rc.kin when its replays are done.
    ReplaySeries series;
    series.source = rc.source;
    series.t = std::move(rc.kin.t);
    series.t_start = rc.kin.t_start;
    for (int j = 0; j < 2; ++j) series.q[j] = std::move(rc.kin.q[j]);
    struct GiveBack {
      ReplaySeries& s;
      Kinematics& kin;
      ~GiveBack() {
        kin.t = std::move(s.t);
        for (int j = 0; j < 2; ++j) kin.q[j] = std::move(s.q[j]);
      }
    } give_back{series, rc.kin};
    CompleteReplaySeries(tau_S, rigid_fx, opt.replay_cutoff_hz, &series);
    const std::vector<double>& t = series.t;
    auto Score = [](const ReplayScore& b, const ReplayScore& a, JointScore out[2]) {
      for (int j = 0; j < 2; ++j) out[j] = ScoreOf(b.sse[j], a.sse[j], static_cast<double>(std::max<size_t>(1, b.count)));
    };
    const bool split_long = t.back() - t[rc.split] >= opt.replay_horizon_s;
    const bool whole_long = D.leave_one_out && t.back() - t.front() >= opt.replay_horizon_s;
    const long from = static_cast<long>(rc.split);
    // The rigid twin and the other (extended, or the left-out fit's) replayed side by side on
    // DiagnoseThreads threads (ReplayTwoTwins: the one done first takes the other's last windows on a
    // second plant alike), the other's input re-formed for its sensor effects into its own vectors.
    const int threads = DiagnoseThreads(opt);
    std::vector<double> tau_other[2];
    auto Second = [&](const LegParams& model, std::unique_ptr<Plant>* p) {
      return [&opt, &model, p]() -> Plant& {
        if (!*p) *p = MakeReplayPlant(model, "the second thread's plant", opt.mjcf);
        return **p;
      };
    };
    // The other twin's input: the series' own where its sensor effects are the model's (the same
    // numbers, without a record-long copy), else re-formed.
    auto OtherInput = [&](const PlantEffects& fx) -> const std::vector<double>* {
      if (fx.sensor[0] == rigid_fx.sensor[0] && fx.sensor[1] == rigid_fx.sensor[1]) return nullptr;
      ActuatorTorqueFromReading(fx, t, tau_S, tau_other);
      return tau_other;
    };
    if (split_long) {
      std::unique_ptr<Plant> rigid2, ext2;
      const ReplayTwin twins[2] = {{rigid.get(), Second(params, &rigid2), nullptr},
                                   {ext.get(), Second(D.extended, &ext2), OtherInput(ext_fx)}};
      std::array<ReplayRecord, 2> ba = ReplayTwoTwins(twins, series, opt.replay_horizon_s, threads, rc.split, n);
      ReplayRecord &b = ba[0], &a = ba[1];
      Score(b.score, a.score, rs.sim_split);
      rs.sim_split_windows = b.score.windows;
      sb.Add(b.score), sa.Add(a.score);
      if (r == 0) {
        S.t.assign(t.begin() + from, t.end());
        for (int j = 0; j < 2; ++j) {
          S.rigid[j] = std::move(b.sim[j]);  // samples rc.split .. n, as S.t
          S.measured[j].assign(series.q[j].begin() + from, series.q[j].end());
          S.extended[j] = std::move(a.sim[j]);
        }
      }
    }
    if (whole_long) {
      LegParams loo = params;
      loo.effects = rs.left_out_effects;
      std::unique_ptr<Plant> loo_plant;
      PlantEffects loo_fx;
      if (!Make(loo, rc.source + " left out", &loo_plant, &loo_fx)) return;
      std::unique_ptr<Plant> rigid2, loo2;
      const ReplayTwin twins[2] = {{rigid.get(), Second(params, &rigid2), nullptr},
                                   {loo_plant.get(), Second(loo, &loo2), OtherInput(loo_fx)}};
      const std::array<ReplayRecord, 2> ba = ReplayTwoTwins(twins, series, opt.replay_horizon_s, threads);
      const ReplayScore &b = ba[0].score, &a = ba[1].score;
      Score(b, a, rs.sim_left_out);
      rs.sim_left_out_windows = b.windows;
      lb.Add(b), la.Add(a);
    }
  }
  for (int j = 0; j < 2; ++j) {
    S.split[j] = ScoreOf(sb.sse[j], sa.sse[j], static_cast<double>(std::max<size_t>(1, sb.count)));
    S.left_out[j] = ScoreOf(lb.sse[j], la.sse[j], static_cast<double>(std::max<size_t>(1, lb.count)));
  }
  S.done = sb.windows > 0 || lb.windows > 0;
  std::ostringstream os;
  os << "the rigid and the extended twin (their effects in the MuJoCo plant, joint limits off) driven by the "
        "measured torque, restarted every " << NumberText(opt.replay_horizon_s)
     << " s from the measured state (the measured angle and its velocity, derived at " << NumberText(opt.replay_cutoff_hz)
     << " Hz, zero-phase 2nd-order Butterworth; a strap run in over its settling time): " << sb.windows << " windows on the held-out parts"
     << (D.leave_one_out ? ", " + std::to_string(lb.windows) + " on the whole records left out" : std::string());
  S.note = S.done ? os.str() : "not simulated: every part is shorter than the horizon of " + NumberText(opt.replay_horizon_s) + " s";
}

// Stage 7: structure the extended twin leaves in the first record's held-out residual torque
// (StructureLeft, diagnose_unexplained.h: the floor kUnexplainedFloorTorque) into D->unexplained.
// Needs D->kin, split, measured, after.
void FindUnexplained(Diagnosis* D_out) {
  Diagnosis& D = *D_out;
  const Kinematics& kin = D.kin;
  const size_t n = kin.t.size();
  const double dt = (kin.t.back() - kin.t.front()) / static_cast<double>(n - 1);
  const double fs = 1.0 / dt;
  for (int j = D.extended.one_joint ? 1 : 0; j < 2; ++j) {
    std::vector<double> full(n, 0.0);
    for (size_t i = D.split; i < n; ++i) full[i] = D.measured[j][i] - D.after[j][i];
    const HeldOutResidual r{kin.t, full, kin.q[j], kin.qd[j], kin.qdd[j], D.split, n, fs};
    if (auto u = StructureLeft(r, j, D.noise[j], kUnexplainedFloorTorque, D.joints[j].rmse_before))
      D.unexplained.push_back(*u);
  }
}

// The method in words, for the report (D.cutoff, D.leave_one_out and the options).
std::string MethodText(const Diagnosis& D, const DiagnoseOptions& opt) {
  std::ostringstream m_os;
  m_os << (D.cutoff.from_columns
               ? std::string("derivatives from the measured qd/qdd columns, no filter")
               : "measured minus predicted torque low-passed at " + NumberText(D.cutoff.hz) +
                     " Hz (zero-phase 2nd-order Butterworth, parallel filtering), angles differentiated at " +
                     NumberText(kDerivativeCutoffFactor * D.cutoff.hz) + " Hz (at most 0.4 fs)")
       << "; time split: fit on the first " << 100 * (1 - opt.holdout_fraction)
       << " % of every record, rmse by the extended twin (predict) on the last " << 100 * opt.holdout_fraction
       << " %" << (D.leave_one_out ? "; every whole record also left out in turn" : "")
       << "; every DESIGN effect per joint as a linearized least-squares candidate (ripple frequency"
          " by grid + golden search; delay, backlash, strap stiffness refined by golden search on the"
          " exact model); forward selection with backward elimination of up to " << opt.max_effects
       << " effects fitted together, each significant (|t| > " << kMinT << "), inside its physical range,"
          " lowering BIC (effective sample size from the residual autocorrelation) by more than "
       << kBicMargin << " and the held-out error at its joint by at least " << 100 * kMinHeldoutGain
       << " % and by (" << 100 * kMinTorqueShare << " % of the torque RMS)^2; fewer parameters preferred unless the richer effect lowers the held-out error by more than "
       << 100 * kParsimony << " %";
  return m_os.str();
}

}  // namespace

namespace {

// The stages of diagnose.h's method, in order; EXOTWIN_DIAG_TIMING=1 prints each one's wall and CPU
// time and the process's peak memory at its end to stderr. Diagnose of `records`; with `owned` (the same records, which the caller gives up), each record's
// columns are moved into the analysis once the cutoff is chosen instead of copied.
Diagnosis DiagnoseRecords(const LegParams& params, const std::vector<const MeasuredData*>& records,
                          std::vector<MeasuredData>* owned, const DiagnoseOptions& opt) {
  if (opt.fit == DiagnoseFit::kMotion) return DiagnoseByMotion(params, records, opt);
  const bool timing = std::getenv("EXOTWIN_DIAG_TIMING") != nullptr;
  auto CpuSeconds = [](const rusage& ru) {
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  };
  auto clock0 = std::chrono::steady_clock::now();
  rusage ru0{};
  getrusage(RUSAGE_SELF, &ru0);
  double cpu0 = CpuSeconds(ru0);
  // Every stage's end gives the heap's free pages back (ReturnFreedMemory), so that the next stage's
  // temporaries take returned pages, not pages on top of what the last one freed: the peak memory
  // is that of the live vectors.
  auto Lap = [&](const char* what) {
    ReturnFreedMemory();
    if (!timing) return;
    const auto now = std::chrono::steady_clock::now();
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    const double cpu = CpuSeconds(ru);
    long pages = 0, resident = 0;  // the memory held at the stage's end (/proc/self/statm, pages)
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
      std::fclose(f);
    }
    std::fprintf(stderr, "diagnose: %-28s %8.3f s (CPU %.3f s), peak %6.1f MB, held %6.1f MB\n", what,
                 std::chrono::duration<double>(now - clock0).count(), cpu - cpu0, ru.ru_maxrss / 1024.0,
                 static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1048576.0);
    clock0 = now;
    cpu0 = cpu;
  };
  CheckInputs(records, opt);
  Diagnosis D;
  D.holdout_fraction = opt.holdout_fraction;
  const size_t R = records.size();
  D.leave_one_out = R >= 2;

  Lap("records read");  // what reading the records freed, before the cutoff choice lays out its columns
  D.cutoff = ResolveCutoff(params, records, opt);
  Lap("cutoff choice");

  Plant plant(opt.mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : opt.mjcf);
  plant.SetParams(params);  // validates the realization
  std::vector<Rec> recs(R);  // in place: Rec::FilterFn captures its record
  for (size_t r = 0; r < R; ++r)
    PrepareRecord(params, *records[r], owned ? &(*owned)[r] : nullptr, D.cutoff, opt.holdout_fraction,
                  DiagnoseThreads(opt), &recs[r]);
  double w[2];
  NoiseAndWeights(recs, D.noise, w);
  if (params.one_joint) w[0] = 0, D.noise[0] = 0;  // one joint: the embedding's held hip is no data
  for (Rec& rc : recs)  // the rigid torque is needed only where stage 5 refines (a long record's memory)
    for (int j = 0; j < 2; ++j) {
      rc.tau_R[j].resize(RefineRows(rc, R));
      rc.tau_R[j].shrink_to_fit();
    }
  Lap("kinematics + twin");

  std::vector<ColumnBank> banks = CandidateColumns(params, recs, w, opt);
  Lap("columns + ripple search");
  FilterMeasured(&recs);
  UseSecantColumns(recs, w, &banks);
  ReturnFreedMemory();  // the secant columns' record-long temporaries
  if (params.one_joint) KeepJointCandidates(1, &banks);
  // The ceilings and the pooled Grams only read the banks: the two side by side.
  std::vector<CeilingScores> ceilings;
  Grams g;
  ParallelFor(2, DiagnoseThreads(opt), [&](size_t k) {
    if (k == 0) g = PooledGrams(recs, banks, w, &D.tau_eff);
    else ceilings = Ceilings(banks, w);
  });
  Lap("ceilings + grams");
  for (ColumnBank& b : banks) b.X = Eigen::MatrixXd(), b.r = Eigen::VectorXd();  // the Grams hold what the fits use
  ReturnFreedMemory();  // the banks' and the workers' blocks, before the twins lay out theirs
  const ColumnBank& bank = banks[0];  // candidates and column indices (identical in every bank)

  const PhysicalScale scale = ScaleOf(params, recs);
  const Fit f0 = FitCols(g, {});
  Fit chosen_fit;
  SelectionTrace trace;
  const std::vector<int> chosen = SelectEffects(bank, g, scale, opt.max_effects, D.leave_one_out, &chosen_fit, &trace);
  D.selection = trace.steps;
  ScoreCandidates(bank, g, scale, f0, chosen, chosen_fit, &D);
  Lap("selection");

  const std::vector<double> refine_ratio = ExtendAndRefine(params, recs, w, bank, g, f0, chosen, chosen_fit, &D);
  FindAliases(bank, g, scale, chosen, chosen_fit, &D);
  Lap("refinement");
  // Stage 5c: the residual tests and ceiling of the table's best model; where it is incomplete, the
  // search for terms beyond the table at those joints.
  Stage5c st = opt.assess ? AssessAndSearch(params, recs, w, banks, scale, opt, &D) : Stage5c{};
  Lap("completeness + terms beyond the table");

  // Each final effect's equivalent reading (FitFamily::equivalent), among its aliases.
  for (DiagnosedEffect& de : D.effects) {
    EffectAlias a;
    const FitFamily& f = FitFamilyOf(de.effect.name);
    if (f.equivalent && f.equivalent(de, D.effects, &a)) de.aliases.insert(de.aliases.begin(), a);
  }
  ScoreExtendedTwin(params, recs, bank, g, chosen, refine_ratio, st.searched.left_out, opt, &D);
  Lap("extended twin");
  // Stage 6c: the final model's (the table's where the search admitted no term), and both ceilings.
  if (st.searched.changed) D.final_model = torque_fit::TestModel(params, D.extended, recs, opt, &st.rows, nullptr);
  if (opt.assess && (st.tests_decide || st.searched.changed)) {
    ModelAssessment again;  // the table's column again where its ceiling was fitted before (one fit)
    torque_fit::FitCeilings(st.rows, {st.tests_decide ? &D.table_model : &again, &D.final_model}, opt);
  }
  if (!st.searched.changed) D.final_model = D.table_model;
  Lap("final completeness + ceiling");
  for (Rec& rc : recs) rc.kin.emg.clear();  // done with: the simulation and the report read no envelope
  for (size_t r = 0; r < R; ++r)
    for (int j = 0; j < 2; ++j) D.records[r].ceiling[j] = ceilings[r].ceiling[j], D.records[r].ceiling_null[j] = ceilings[r].null[j];
  // Effects in order of what they explain.
  std::stable_sort(D.effects.begin(), D.effects.end(), [](const DiagnosedEffect& a, const DiagnosedEffect& b) {
    return a.explained_pct > b.explained_pct;
  });
  D.extended.effects.resize(params.effects.size());
  for (const auto& de : D.effects) D.extended.effects.push_back(de.effect);
  SimulateTwins(params, recs, opt, &D);
  D.kin = std::move(recs[0].kin);  // recs are done with: the plot series take the first record's kinematics
  D.split = recs[0].split;
  Lap("forward simulation");

  FindUnexplained(&D);
  Lap("unexplained");
  D.method = MethodText(D, opt);
  return D;
}

}  // namespace

Diagnosis Diagnose(const LegParams& params, const std::vector<const MeasuredData*>& records,
                   const DiagnoseOptions& opt) {
  return DiagnoseRecords(params, records, nullptr, opt);
}

Diagnosis Diagnose(const LegParams& params, std::vector<MeasuredData>&& records, const DiagnoseOptions& opt) {
  std::vector<const MeasuredData*> pointers;
  for (const MeasuredData& m : records) pointers.push_back(&m);
  return DiagnoseRecords(params, pointers, &records, opt);
}

}  // namespace exotwin
