// `exotwin diagnose --fit motion` (motion_fit.h): DiagnoseByMotion as its phases, in order; the set-up
// (step 1), the held-out gate (step 6), the intervals (step 7) and the scores (the given, the extended
// and the torque fit's twin, what the torque fit alone names, the structure left). The rounds (steps
// 2-5) are in motion_rounds.cc.
#include "diagnosis/motion_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "core/rng.h"
#include "diagnosis/diagnose_internal.h"
#include "diagnosis/diagnose_unexplained.h"
#include "diagnosis/motion_fit_internal.h"
#include "formats/number_text.h"

namespace exotwin {
namespace motion {

std::string Labels(const MotionProblem& P, const std::vector<int>& set) {
  std::string o;
  for (int c : set) o += (o.empty() ? "" : " + ") + P.candidates()[static_cast<size_t>(c)].Label();
  return o.empty() ? "the model given" : o;
}

std::string ValueText(const MotionProblem& P, const Candidate& cand, const Eigen::VectorXd& theta) {
  Eigen::VectorXd only = Eigen::VectorXd::Zero(theta.size());
  for (int k : cand.cols) only[k] = theta[k];
  std::string o;
  for (const Effect& e : P.EffectsOf(only)) {
    o += (o.empty() ? "" : ", ") + NumberText(e.value, 4) + " " + e.unit;
    if (e.fields.count("phase")) o += " (phase " + NumberText(e.fields.at("phase"), 3) + " rad)";
  }
  if (o.empty())
    for (int k : cand.cols) o += (o.empty() ? "" : " ") + NumberText(theta[k], 4);
  return o;
}

namespace {

// Held-out scores of the simulated angle (rad), at least one sample counted.
JointScore Score(double sse_before, double sse_after, double count) {
  return ScoreOf(sse_before, sse_after, std::max(count, 1.0));
}

// Step 1's torque fit (Diagnose with DiagnoseFit::kTorque, no simulation), the records checked first.
Diagnosis TorqueFitOf(const LegParams& params, const std::vector<const MeasuredData*>& records, const DiagnoseOptions& opt) {
  bool by_reading = true;
  for (const MeasuredData* data : records) CheckMotionRecord(params, *data, opt, &by_reading);
  // 1. The torque fit: starting values and what it would name.
  DiagnoseOptions topt = opt;
  topt.fit = DiagnoseFit::kTorque;
  topt.simulate = false;
  topt.search_terms = false;  // the motion fit searches no terms: its start and floor are the table's model
  Diagnosis T = Diagnose(params, records, topt);
  return T;
}

}  // namespace

MotionFit::MotionFit(const LegParams& params, const std::vector<const MeasuredData*>& records,
                     const DiagnoseOptions& opt)
    : params(params),
      records(records),
      opt(opt),
      T(TorqueFitOf(params, records, opt)),
      P(params, records, opt, T.effects),
      n_par(P.parameters()),
      cands(P.candidates()),
      loo(records.size() >= 2) {
  cand_bank.candidates = cands;
  all.resize(static_cast<size_t>(n_par));
  for (int k = 0; k < n_par; ++k) all[static_cast<size_t>(k)] = k;

  D.fit = DiagnoseFit::kMotion;
  D.holdout_fraction = opt.holdout_fraction;
  D.leave_one_out = loo;
  D.torque_named = T.effects;
  D.cutoff = T.cutoff;

  zero = Eigen::VectorXd::Zero(n_par);
  given = P.Simulate(zero, Part::kBoth);
  Charge(kSetUp);
  if (!given.ok) throw SimulationError(0, "the model given diverges in the forward simulation of the records");
  {
    double rows = 0, windows = 0;
    for (size_t r = 0; r < P.records(); ++r) {
      rows += static_cast<double>(P.rows(r).size());
      windows += static_cast<double>(P.windows(r, Part::kBoth));
    }
    window_rows = rows / std::max(windows, 1.0);
  }
  theta = zero;
  at = given;
  wv = RowWeights(P);
}

void MotionFit::Charge(Stage st) {
  const double now = P.ReplaysSimulated();
  cost[st] += now - mark;
  mark = now;
}

void MotionFit::HeldOutGate() {
  explained.assign(chosen.size(), 0.0);
  P.Sse(given, Part::kHeldOut, sse_given_te);
  while (!chosen.empty()) {
    // A refined value outside its range (DESIGN.md's table: the selection checked the linear fit's)
    // goes first; else the effect whose removal raises the error at its joint least (of the held-out
    // ends, or with several records the better of that and the whole records left out), if below
    // kMinHeldoutGain.
    std::string why;
    int drop = OutOfRange(&why);
    if (drop < 0) drop = WeakestEffect(&why);
    if (drop < 0) break;
    D.selection.push_back(why);
    for (int k : cands[static_cast<size_t>(chosen[static_cast<size_t>(drop)])].cols) theta[k] = 0;
    chosen.erase(chosen.begin() + drop);
    have_last = false;
    if (chosen.empty()) {
      theta = zero;
      break;
    }
    const Refined rf = Refine(P, ColumnsOf(cand_bank, chosen), {theta});
    if (std::isfinite(rf.cost)) theta = rf.theta, last = rf, have_last = true;
  }
  at = P.Simulate(theta, Part::kBoth);
  if (!at.ok) throw SimulationError(0, "the motion fit's extended twin diverges on the records");
  Charge(kGate);
}

void MotionFit::TorqueTwinFloor() {
  // 6b. The torque fit's twin (its effects at its values, those the plant carries) against the current
  // set on the held-out parts, unweighted RMS per joint: the final comparison (ScoreTorqueFitTwin).
  std::vector<Effect> named;
  std::vector<int> tset;  // their candidates
  for (const DiagnosedEffect& d : T.effects) {
    named.push_back(d.effect);
    Eigen::VectorXd probe = zero;
    const int c = CandidateOf(P, d.effect);
    if (c >= 0 && TorqueValues(P, d.effect, &probe) && std::find(tset.begin(), tset.end(), c) == tset.end())
      tset.push_back(c);
  }
  if (tset.empty()) return;
  const Eigen::VectorXd tx = TorqueTwinTheta(named, nullptr);
  const MotionProblem::Rollout tro = P.Simulate(tx, Part::kHeldOut);
  double now[2], tq[2];
  HeldOutRms(at, now);
  if (!tro.ok) return;
  HeldOutRms(tro, tq);
  const int j0 = params.one_joint ? 1 : 0;
  auto Within = [&](const double rms[2]) {
    for (int j = j0; j < 2; ++j)
      if (!(rms[j] <= kTorqueTwinTolerance * tq[j])) return false;
    return true;
  };
  auto Deg = [&](const double rms[2]) {
    std::string o;
    for (int j = j0; j < 2; ++j)
      o += std::string(j == j0 ? "" : ", ") + kJoint[j] + " " + NumberText(rms[j] * 180 / M_PI, 4);
    return o + " deg";
  };
  if (Within(now)) return;
  const std::string head = "the torque fit's twin (" + Labels(P, tset) + ") replays the held-out rows at " + Deg(tq) +
                           ", " + Labels(P, chosen) + " at " + Deg(now) + " (more than " +
                           NumberText(kTorqueTwinTolerance) + "x at a joint): ";
  // The options, each starting from the torque fit's effects at its values: refined on the fit part;
  // held at its values with the motion fit's effects that conflict with none of them added, those
  // refined alone; the current set with the torque fit's effects that conflict with none of it added,
  // all refined; at its values (its twin itself, within the tolerance by construction). `held`: the
  // parameters left at the torque fit's values.
  struct Option {
    std::string what;
    std::vector<int> set;
    Eigen::VectorXd theta;
    std::vector<int> held;
  };
  const std::vector<int> tcols = ColumnsOf(cand_bank, tset);
  auto Clash = [&](const std::vector<int>& set, int c) {
    return std::any_of(set.begin(), set.end(), [&](int s) {
      return s == c || Conflicts(cands[static_cast<size_t>(s)], cands[static_cast<size_t>(c)]);
    });
  };
  // Set `a` at values xa with the effects of set `b` that conflict with none of it added at values xb.
  auto Union = [&](const std::vector<int>& a, const Eigen::VectorXd& xa, const std::vector<int>& b,
                   const Eigen::VectorXd& xb, Eigen::VectorXd* x) {
    std::vector<int> u = a;
    *x = xa;
    for (int c : b) {
      if (Clash(u, c)) continue;
      u.push_back(c);
      for (int k : cands[static_cast<size_t>(c)].cols) (*x)[k] = xb[k];
    }
    return u;
  };
  std::vector<Option> options;
  {
    const Refined ra = Refine(P, tcols, {tx}, kMotionLmIterations, false);
    if (std::isfinite(ra.cost)) options.push_back({"its effects refined on the fit part", tset, ra.theta, {}});
    Eigen::VectorXd dx, ux;
    const std::vector<int> dset = Union(tset, tx, chosen, theta, &dx);
    if (dset.size() > tset.size()) {
      const std::vector<int> added(dset.begin() + static_cast<long>(tset.size()), dset.end());
      const Refined rd = Refine(P, ColumnsOf(cand_bank, added), {dx}, kMotionLmIterations, false);
      if (std::isfinite(rd.cost))
        options.push_back({"its effects at its values, the motion fit's others added and refined", dset, rd.theta, tcols});
    }
    const std::vector<int> uset = Union(chosen, theta, tset, tx, &ux);
    if (uset.size() > chosen.size() && !chosen.empty()) {
      const Refined rb = Refine(P, ColumnsOf(cand_bank, uset), {ux}, kMotionLmIterations, false);
      if (std::isfinite(rb.cost)) options.push_back({"its effects added to the set, refined", uset, rb.theta, {}});
    }
    options.push_back({"its effects at its values", tset, tx, tcols});
  }
  std::vector<Eigen::VectorXd> xs;
  for (const Option& o : options) xs.push_back(o.theta);
  const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(xs, Part::kBoth);
  int best = -1;
  double best_bic = INFINITY;
  for (size_t k = 0; k < options.size(); ++k) {
    if (!ro[k].ok) {
      D.selection.push_back(head + options[k].what + ": the plant cannot simulate them");
      continue;
    }
    double rms[2];
    HeldOutRms(ro[k], rms);
    const double bic = ExactBic(Cost(P, ro[k], Part::kFit), ParameterCount(options[k].set));
    const bool within = Within(rms);
    D.selection.push_back(head + options[k].what + " (" + Labels(P, options[k].set) + "): held-out " + Deg(rms) +
                          ", exact fit-part BIC " + NumberText(bic, 4) + (within ? "" : ", still worse"));
    if (within && bic < best_bic) best_bic = bic, best = static_cast<int>(k);
  }
  if (best < 0) {
    floor_note = "the torque fit's effects, refined or at its values, could not be simulated on the records";
    return;
  }
  const Option& o = options[static_cast<size_t>(best)];
  D.selection.push_back("taken: " + o.what + " (" + Labels(P, o.set) + "), the lowest exact fit-part BIC within " +
                        NumberText(kTorqueTwinTolerance) + "x the torque fit's twin");
  chosen = o.set, theta = o.theta, at = ro[static_cast<size_t>(best)];
  held = o.held, have_last = false;
  floor_note = "the torque fit's twin, " + o.what + ", was taken in place of the motion fit's set" +
               (held.empty() ? std::string("; its values moved when refined under the extended twin's own misfit")
                             : std::string("; the held-out gate removed what gained too little there"));
  // The held-out gate on this set, read against the torque fit's twin: an effect that gains less than
  // kMinHeldoutGain at its joint goes only where the set without it still replays within the tolerance.
  for (std::string why; !chosen.empty();) {
    const int drop = WeakestEffect(&why);
    if (drop < 0) break;
    Eigen::VectorXd x = theta;
    for (int k : cands[static_cast<size_t>(chosen[static_cast<size_t>(drop)])].cols) {
      x[k] = 0;
      held.erase(std::remove(held.begin(), held.end(), k), held.end());
    }
    MotionProblem::Rollout rx = P.Simulate(x, Part::kBoth);
    double rms[2] = {INFINITY, INFINITY};
    if (rx.ok) HeldOutRms(rx, rms);
    if (!Within(rms)) {
      D.selection.push_back("kept against the " + why + ": without it the twin replays the held-out rows at " + Deg(rms) +
                            ", beyond " + NumberText(kTorqueTwinTolerance) + "x the torque fit's twin");
      break;
    }
    D.selection.push_back(why + " (the rest still within " + NumberText(kTorqueTwinTolerance) + "x the torque fit's twin)");
    chosen.erase(chosen.begin() + drop);
    theta = x, at = std::move(rx);
  }
  Charge(kGate);
}

int MotionFit::OutOfRange(std::string* why) const {
  int drop = -1;
  for (size_t k = 0; k < chosen.size() && drop < 0; ++k) {
    const Candidate& c = cands[static_cast<size_t>(chosen[k])];
    Eigen::VectorXd coef(static_cast<Eigen::Index>(c.cols.size()));
    for (size_t i = 0; i < c.cols.size(); ++i) coef[static_cast<Eigen::Index>(i)] = theta[c.cols[i]];
    if (!Plausible(ToEffect(c, coef, c.cols), P.scale(), why)) {
      drop = static_cast<int>(k);
      *why = "range: " + c.Label() + " removed at its refined value: " + *why;
    }
  }
  return drop;
}

int MotionFit::WeakestEffect(std::string* why) {
  int drop = -1;
  std::vector<Eigen::VectorXd> thetas = {theta};
  for (int c : chosen) {
    Eigen::VectorXd x = theta;
    for (int k : cands[static_cast<size_t>(c)].cols) x[k] = 0;
    thetas.push_back(x);
  }
  // With several records, both parts: the fit part's residual gives the values each record left
  // out takes (LeftOutThetas), whose whole-record error is the second test.
  const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(thetas, loo ? Part::kBoth : Part::kHeldOut);
  double full[2];
  P.Sse(ro[0], Part::kHeldOut, full);
  const std::vector<std::array<double, 2>> left_out =
      loo && ro[0].ok ? LeftOutErrors(thetas, ro) : std::vector<std::array<double, 2>>(thetas.size(), {NAN, NAN});
  double worst_gain = INFINITY, worst_held = 0, worst_left = NAN;
  explained.assign(chosen.size(), 0.0);
  for (size_t k = 0; k < chosen.size(); ++k) {
    const int j = cands[static_cast<size_t>(chosen[k])].joint;
    double without[2] = {INFINITY, INFINITY};
    if (ro[k + 1].ok) P.Sse(ro[k + 1], Part::kHeldOut, without);
    const double held = without[j] > 0 ? 1 - full[j] / without[j] : 0.0;
    // Records left out (several records): kept where either test gains kMinHeldoutGain (a record's
    // held-out end may lack the motion an effect shows in, which the other records carry).
    const double left = left_out[0][j] / left_out[k + 1][j];
    const double gain = std::isfinite(left) && left_out[k + 1][j] > 0 ? std::max(held, 1 - left) : held;
    explained[k] = 100 * ((without[0] + without[1]) - (full[0] + full[1])) /
                   std::max(sse_given_te[0] + sse_given_te[1], 1e-300);
    if (gain < worst_gain)
      worst_gain = gain, worst_held = held, worst_left = std::isfinite(left) ? 1 - left : NAN, drop = static_cast<int>(k);
  }
  if (worst_gain >= kMinHeldoutGain) return -1;
  const Candidate& wc = cands[static_cast<size_t>(chosen[static_cast<size_t>(drop)])];
  *why = "exact held-out gate: " + wc.Label() + " removed: without it the held-out simulated error at the " +
        kJoint[wc.joint] + " is only " + NumberText(100 * worst_held, 3) + " % higher" +
        (std::isfinite(worst_left) ? ", the records' left out " + NumberText(100 * worst_left, 3) + " %" : "") +
        " (needed " + NumberText(100 * kMinHeldoutGain) + " %)";
  return drop;
}

std::vector<std::array<double, 2>> MotionFit::LeftOutErrors(const std::vector<Eigen::VectorXd>& thetas,
                                                            const std::vector<MotionProblem::Rollout>& ro) {
  std::vector<std::array<double, 2>> left_out(thetas.size(), {NAN, NAN});
  const std::vector<int> cols = ColumnsOf(cand_bank, chosen);
  const Eigen::MatrixXd J = WeightedFitJacobian(P, theta, ro[0], cols);
  const std::vector<Eigen::Index> fit_rows = PartRows(P, Part::kFit);
  for (size_t set = 0; set < thetas.size(); ++set) {
    if (!ro[set].ok) continue;
    std::vector<int> cs;
    std::vector<Eigen::Index> keep;
    for (size_t c = 0; c < cols.size(); ++c) {
      const auto& out = set == 0 ? std::vector<int>{} : cands[static_cast<size_t>(chosen[set - 1])].cols;
      if (std::find(out.begin(), out.end(), cols[c]) != out.end()) continue;
      cs.push_back(cols[c]);
      keep.push_back(static_cast<Eigen::Index>(c));
    }
    Eigen::MatrixXd Js(J.rows(), static_cast<Eigen::Index>(keep.size()));
    for (size_t c = 0; c < keep.size(); ++c) Js.col(static_cast<Eigen::Index>(c)) = J.col(keep[c]);
    int bad = -1;
    const std::vector<Eigen::VectorXd> lt =
        cs.empty() ? std::vector<Eigen::VectorXd>(P.records(), thetas[set])
                   : LeftOutThetas(P, thetas[set], cs, Js, WeightedResidual(P, ro[set], fit_rows), &bad);
    if (bad >= 0) continue;
    const std::vector<MotionProblem::Rollout> lro = P.SimulateEachRecord(lt);
    std::array<double, 2> sum = {0, 0};
    for (size_t r = 0; r < lro.size() && std::isfinite(sum[0]); ++r) {
      double a[2] = {NAN, NAN}, n;
      if (lro[r].ok) P.RecordSse(lro[r], r, Part::kBoth, a, &n);
      sum[0] += a[0], sum[1] += a[1];
    }
    left_out[set] = sum;
  }
  return left_out;
}

void MotionFit::Intervals() {
  // 7. Values and intervals from the final Jacobian: the set's values refined once more with the
  // weights of the extended twin's own misfit (motion_fit.h "Output weights").
  cols = ColumnsOf(cand_bank, chosen);
  if (!chosen.empty()) {
    const double before[2] = {P.weight(0), P.weight(1)};
    P.WeightBy(at);
    have_last = false;
    std::string text = "values refined with the extended twin's misfit as the output weights:";
    for (int j = params.one_joint ? 1 : 0; j < 2; ++j)
      text += std::string(" ") + kJoint[j] + " " + NumberText(1 / P.weight(j), 4) + " rad (was " + NumberText(1 / before[j], 4) + ")";
    D.selection.push_back(text);
  }
  D.tau_eff = ResidualAutocorrelation(P, at, window_rows);
  if (!chosen.empty()) {
    if (!held.empty()) {  // step 6b held the torque fit's values: the rest refined, the Jacobian at all
      std::vector<int> free;
      for (int k : cols)
        if (std::find(held.begin(), held.end(), k) == held.end()) free.push_back(k);
      if (!free.empty()) {
        const Refined rf = Refine(P, free, {theta}, kMotionLmIterations, false);
        if (std::isfinite(rf.cost)) theta = rf.theta, at = P.Simulate(theta, Part::kBoth);
      }
      last.theta = theta;
      last.cost = Cost(P, at, Part::kFit);
      last.J = WeightedFitJacobian(P, theta, at, cols);
      last.e = WeightedResidual(P, at, PartRows(P, Part::kFit));
    } else if (!have_last) {
      last = Refine(P, cols, {theta});  // with the new weights (from theta, its band probes)
    }
    theta = last.theta;
    at = P.Simulate(theta, Part::kBoth);
    Fit f;
    f.ok = true;
    f.cols = cols;
    f.coef.resize(static_cast<Eigen::Index>(cols.size()));
    for (size_t k = 0; k < cols.size(); ++k) f.coef[static_cast<Eigen::Index>(k)] = theta[cols[k]];
    const double n = static_cast<double>(last.e.size()), p = static_cast<double>(cols.size());
    const double s2 = last.e.squaredNorm() / std::max(n - p, 1.0) * D.tau_eff;
    const Eigen::MatrixXd A = last.J.transpose() * last.J;
    const Eigen::MatrixXd cov = s2 * A.ldlt().solve(Eigen::MatrixXd::Identity(A.rows(), A.cols()));
    f.se = cov.diagonal().cwiseMax(0).cwiseSqrt();
    for (size_t k = 0; k < chosen.size(); ++k) {
      DiagnosedEffect de = ToEffect(cands[static_cast<size_t>(chosen[k])], f);
      de.explained_pct = explained[k];
      D.effects.push_back(de);
    }
    Spread();
    TorqueFitSpread();
  }
  ExtendedTwin(params, &D);
}

void MotionFit::ScoreTwins() {
  // Scores: the given vs the extended twin, held-out parts and whole records left out (rad).
  SimulationScores& S = D.simulation;
  S.horizon_s = opt.replay_horizon_s;
  S.cutoff_hz = 0;
  for (const MeasuredData* data : records) S.cutoff_hz = std::max(S.cutoff_hz, MotionCutoff(opt, *data));
  double sb[2] = {0, 0}, sa[2] = {0, 0}, cnt = 0, lb[2] = {0, 0}, la[2] = {0, 0}, lcnt = 0;
  // Each record left out in turn: the values one Gauss-Newton step from the final ones on the other
  // records' fit parts (the final refinement's Jacobian and residual; the round's linear model g_last
  // is linearized where that round started, which the rounds' choice and the exchanges may have left
  // far behind), each simulated on its record.
  std::vector<Eigen::VectorXd> loo_thetas;
  if (loo) {
    int bad = -1;
    if (cols.empty()) loo_thetas.assign(P.records(), theta);
    else loo_thetas = LeftOutThetas(P, theta, cols, last.J, last.e, &bad);
    if (bad >= 0)
      throw InputError(records[static_cast<size_t>(bad)]->source +
                       ": without this record the chosen effects are not identifiable");
  }
  const std::vector<MotionProblem::Rollout> loo_ro = P.SimulateEachRecord(loo_thetas);
  for (size_t r = 0; r < P.records(); ++r) {
    RecordScore rs;
    rs.source = records[r]->source;
    rs.samples = records[r]->size();
    double b[2], a[2], c;
    P.RecordSse(given, r, Part::kHeldOut, b, &c);
    P.RecordSse(at, r, Part::kHeldOut, a, &c);
    rs.sim_split_windows = P.windows(r, Part::kHeldOut);
    for (int j = 0; j < 2; ++j) {
      rs.split[j] = rs.sim_split[j] = Score(b[j], a[j], c);
      sb[j] += b[j], sa[j] += a[j];
    }
    cnt += c;
    if (loo) {
      double lb_r[2], la_r[2], lc;
      P.RecordSse(given, r, Part::kBoth, lb_r, &lc);
      if (!loo_ro[r].ok) throw SimulationError(0, rs.source + ": the effects fitted on the other records diverge on it");
      P.RecordSse(loo_ro[r], r, Part::kBoth, la_r, &lc);
      for (int j = 0; j < 2; ++j) {
        rs.left_out[j] = rs.sim_left_out[j] = Score(lb_r[j], la_r[j], lc);
        lb[j] += lb_r[j], la[j] += la_r[j];
      }
      lcnt += lc;
      rs.sim_left_out_windows = P.windows(r, Part::kBoth);
      rs.left_out_effects = params.effects;
      const std::vector<Effect> fx = P.EffectsOf(loo_thetas[r]);
      rs.left_out_effects.insert(rs.left_out_effects.end(), fx.begin(), fx.end());
    }
    D.records.push_back(rs);
  }
  PlottedSeries();
  for (int j = 0; j < 2; ++j) {
    D.joints[j] = S.split[j] = Score(sb[j], sa[j], cnt);
    if (loo) D.left_out[j] = S.left_out[j] = Score(lb[j], la[j], lcnt);
    D.noise[j] = P.weight(j) > 0 ? 1 / P.weight(j) : 0.0;
  }
  S.done = true;
  {
    std::ostringstream os;
    os << "the model given and the motion fit's extended twin (their effects in the MuJoCo plant, joint limits off) "
          "driven by the measured torque, in quiet windows of " << NumberText(opt.replay_horizon_s)
       << " s (replay --windows quiet) restarted from the measured state (the measured angle and its velocity, derived at "
       << NumberText(S.cutoff_hz)
       << " Hz or a tenth of a record's sample rate, zero-phase 2nd-order Butterworth; a strap run in over its settling "
          "time), on the held-out parts"
       << (loo ? " and on every whole record with the effects fitted on the others" : "");
    S.note = os.str();
  }
}

void MotionFit::PlottedSeries() {
  SimulationScores& S = D.simulation;
  const auto& t = records[0]->t();
  const size_t split = P.rows(0)[P.fit_rows(0)];
  // The held-out part, NaN off the scored rows.
  const size_t n = t.size(), m = P.rows(0).size();
  S.t.assign(t.begin() + static_cast<long>(split), t.end());
  for (int j = 0; j < 2; ++j) {
    S.measured[j].assign(n - split, std::nan(""));
    S.rigid[j] = S.extended[j] = S.measured[j];
    for (size_t k = P.fit_rows(0); k < m; ++k) {
      const size_t i = P.rows(0)[k] - split;
      const Eigen::Index row = static_cast<Eigen::Index>(j * m + k);
      S.measured[j][i] = P.measured(0)[row];
      S.rigid[j][i] = given.q[0][row];
      S.extended[j][i] = at.q[0][row];
    }
  }
}

void MotionFit::ListTorqueOnly() {
  // Torque only: what the torque fit names and the motion fit does not, judged as the final comparison
  // judges twins (unweighted held-out RMS simulated-angle error per joint): added at the torque fit's
  // value to the motion fit's effects, and taken out of the torque fit's twin.
  std::vector<Effect> named;
  for (const DiagnosedEffect& d : T.effects) named.push_back(d.effect);
  std::vector<Eigen::VectorXd> tthetas = {TorqueTwinTheta(named, nullptr)};
  std::vector<size_t> tidx;
  for (size_t k = 0; k < T.effects.size(); ++k) {
    const Effect& e = T.effects[k].effect;
    bool is_named = false;
    for (const auto& de : D.effects)
      is_named = is_named || (de.effect.name == e.name && de.effect.joint == e.joint && de.effect.axis == e.axis);
    if (is_named) continue;
    TorqueOnlyEffect to;
    to.effect = e;
    Eigen::VectorXd x = theta;
    to.simulated = TorqueValues(P, e, &x);
    if (!to.simulated) to.why = P.WhyNoCandidate(e);
    if (to.simulated) {
      for (int c = 0; c < n_par; ++c) x[c] = std::clamp(x[c], P.lower(c), P.upper(c));
      std::vector<Effect> rest = named;
      rest.erase(rest.begin() + static_cast<long>(k));
      tthetas.push_back(x);
      tthetas.push_back(TorqueTwinTheta(rest, nullptr));
      tidx.push_back(D.torque_only.size());
    }
    D.torque_only.push_back(to);
  }
  if (tidx.empty()) return;
  const std::vector<MotionProblem::Rollout> tro = P.SimulateAll(tthetas, Part::kHeldOut);
  double base[2], twin[2];
  HeldOutRms(at, base);
  HeldOutRms(tro[0], twin);
  for (size_t k = 0; k < tidx.size(); ++k) {
    TorqueOnlyEffect& to = D.torque_only[tidx[k]];
    const MotionProblem::Rollout &added = tro[1 + 2 * k], &without = tro[2 + 2 * k];
    if (!added.ok) {
      to.simulated = false;
      to.why = "its rollout failed (the plant refused the values or diverged)";
      continue;
    }
    double s[2], w[2];
    HeldOutRms(added, s);
    for (int j = 0; j < 2; ++j) to.heldout_change_pct[j] = base[j] > 0 ? 100 * (s[j] / base[j] - 1) : 0.0;
    if (!tro[0].ok || !without.ok) continue;
    HeldOutRms(without, w);
    for (int j = 0; j < 2; ++j) to.in_torque_twin_pct[j] = w[j] > 0 ? 100 * (twin[j] / w[j] - 1) : 0.0;
  }
}

void MotionFit::ScoreTorqueFitTwin() {
  // The torque fit's twin on the same rows (SimulationScores::torque_fit_*): its effects, and per
  // record left out its values fitted without that record, as the plant carries them.
  SimulationScores& S = D.simulation;
  if (S.done) {
    std::vector<Effect> named;
    for (const DiagnosedEffect& d : T.effects) named.push_back(d.effect);
    const Eigen::VectorXd t_theta = TorqueTwinTheta(named, &S.torque_fit_not_carried);
    const MotionProblem::Rollout t_ro = P.Simulate(t_theta, Part::kHeldOut);
    std::vector<Eigen::VectorXd> t_loo;
    if (loo)
      for (size_t r = 0; r < P.records(); ++r) {
        const std::vector<Effect>& fx = T.records[r].left_out_effects;
        t_loo.push_back(TorqueTwinTheta(std::vector<Effect>(fx.begin() + static_cast<long>(std::min(params.effects.size(), fx.size())), fx.end()),
                                &S.torque_fit_not_carried));
      }
    const std::vector<MotionProblem::Rollout> t_loo_ro = P.SimulateEachRecord(t_loo);
    bool ok = t_ro.ok;
    for (const auto& ro : t_loo_ro) ok = ok && ro.ok;
    if (ok) {
      double tb[2] = {0, 0}, ta[2] = {0, 0}, tc = 0, ltb[2] = {0, 0}, lta[2] = {0, 0}, ltc = 0;
      for (size_t r = 0; r < P.records(); ++r) {
        double b[2], a[2], c;
        P.RecordSse(given, r, Part::kHeldOut, b, &c);
        P.RecordSse(t_ro, r, Part::kHeldOut, a, &c);
        for (int j = 0; j < 2; ++j) tb[j] += b[j], ta[j] += a[j];
        tc += c;
        if (!loo) continue;
        P.RecordSse(given, r, Part::kBoth, b, &c);
        P.RecordSse(t_loo_ro[r], r, Part::kBoth, a, &c);
        for (int j = 0; j < 2; ++j) ltb[j] += b[j], lta[j] += a[j];
        ltc += c;
      }
      for (int j = 0; j < 2; ++j) {
        S.torque_fit_split[j] = Score(tb[j], ta[j], tc);
        if (loo) S.torque_fit_left_out[j] = Score(ltb[j], lta[j], ltc);
      }
      S.torque_fit_done = true;
      std::string worse;
      for (int j = params.one_joint ? 1 : 0; j < 2; ++j)
        if (S.split[j].rmse_after > kTorqueTwinTolerance * S.torque_fit_split[j].rmse_after)
          worse += std::string(worse.empty() ? "" : ", ") + "the " + kJoint[j] + " " +
                   NumberText(S.split[j].rmse_after * 180 / M_PI, 4) + " deg against " +
                   NumberText(S.torque_fit_split[j].rmse_after * 180 / M_PI, 4);
      if (!worse.empty())
        S.torque_fit_why = "the motion fit's twin replays the held-out rows worse than the torque fit's twin (" + worse +
                           "): " + (floor_note.empty() ? "the torque fit's effects were not put to the plant" : floor_note);
    }
  }
}

Eigen::VectorXd MotionFit::TorqueTwinTheta(const std::vector<Effect>& fx, std::vector<std::string>* not_carried) const {
  Eigen::VectorXd x = zero;
  for (const Effect& e : fx) {
    if (TorqueValues(P, e, &x)) continue;
    const std::string label = e.name + " (" + e.joint + ")";
    if (not_carried && std::find(not_carried->begin(), not_carried->end(), label) == not_carried->end())
      not_carried->push_back(label);
  }
  for (int c = 0; c < n_par; ++c) x[c] = std::clamp(x[c], P.lower(c), P.upper(c));
  return x;
}

void MotionFit::HeldOutRms(const MotionProblem::Rollout& ro, double rms[2]) const {
  double sse[2] = {0, 0}, count = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    double a[2], c;
    P.RecordSse(ro, r, Part::kHeldOut, a, &c);
    sse[0] += a[0], sse[1] += a[1], count += c;
  }
  for (int j = 0; j < 2; ++j) rms[j] = std::sqrt(sse[j] / std::max(count, 1.0));
}

void MotionFit::FindUnexplained() {
  const MeasuredData& data = *records[0];
  const Kinematics kin = DeriveKinematics(data);  // on the record's own samples (MotionProblem's)
  const std::vector<size_t>& rows = P.rows(0);
  const size_t m = rows.size(), mf = P.fit_rows(0), n = data.size();
  const double fs = static_cast<double>(n - 1) / (data.t().back() - data.t().front());
  for (int j = params.one_joint ? 1 : 0; j < 2; ++j) {
    // The scored held-out rows in time order (the windows joined), and the motion there.
    std::vector<double> t, e, q, qd, qdd;
    double diff2 = 0, diffs = 0;
    for (size_t k = mf; k < m; ++k) {
      const size_t i = rows[k];
      const Eigen::Index row = static_cast<Eigen::Index>(j * m + k);
      t.push_back(kin.t[i]), q.push_back(kin.q[j][i]), qd.push_back(kin.qd[j][i]), qdd.push_back(kin.qdd[j][i]);
      e.push_back(P.measured(0)[row] - at.q[0][row]);
      // The white noise from the first differences of consecutive samples (diagnose.cc NoiseAndWeights).
      if (k > mf && rows[k - 1] + 1 == i) diff2 += std::pow(e.back() - e[e.size() - 2], 2), diffs += 1;
    }
    const double noise = std::sqrt(diff2 / (2.0 * std::max(diffs, 1.0)));
    const HeldOutResidual r{t, e, q, qd, qdd, 0, e.size(), fs};
    if (auto u = StructureLeft(r, j, noise, kUnexplainedFloorAngle, D.records[0].split[j].rmse_before))
      D.unexplained.push_back(*u);
  }
}

Diagnosis MotionFit::Finish() {
  Charge(kScores);
  {
    std::ostringstream os;
    os << "simulation, in replays of the records: set-up " << NumberText(cost[kSetUp], 3) << ", Jacobians "
       << NumberText(cost[kJacobians], 3) << ", screening " << NumberText(cost[kScreening], 3) << ", refinement "
       << NumberText(cost[kRefinement], 3) << ", held-out gate " << NumberText(cost[kGate], 3)
       << ", intervals and scores " << NumberText(cost[kScores], 3) << " (" << NumberText(P.ReplaysSimulated(), 4)
       << " in all)";
    D.selection.push_back(os.str());
  }
  D.kin = std::move(T.kin);
  D.split = T.split;
  std::ostringstream m;
  m << "motion fit: the candidate effects' values fitted by simulating the forward plant on the records (multiple "
       "shooting: quiet windows of " << NumberText(opt.replay_horizon_s) << " s, restarted from the measured state, the measured "
       "angle and its velocity derived at " << NumberText(D.simulation.cutoff_hz) << " Hz, where the motion has no fast content "
       "that velocity misses, a dead band's knocks, and scored while it stays so; replay --windows quiet), driven by the "
       "recorded actuator torque ("
    << (P.hold() ? "each sample held over the step" : "interpolated linearly between samples")
    << ", the closer of the two for the model given); outputs the "
       "angles weighted by 1 / the given twin's RMS simulated error per joint (" << NumberText(D.noise[0], 3) << " / "
    << NumberText(D.noise[1], 3) << " rad); fit on the first " << NumberText(100 * (1 - opt.holdout_fraction), 3)
    << " % of every record, held out the rest" << (loo ? ", every whole record also left out in turn" : "")
    << "; selection on the forward-difference Jacobian by the torque fit's gates (BIC margin " << NumberText(kBicMargin)
    << ", |t| > " << NumberText(kMinT) << ", held-out gain >= " << NumberText(100 * kMinHeldoutGain)
    << " %, ranges), values refined by projected Levenberg-Marquardt in the box of the ranges, each named effect "
       "checked on the exact held-out simulation; residual autocorrelation " << NumberText(D.tau_eff, 3) << " rows";
  D.method = m.str();
  return std::move(D);
}

}  // namespace motion

Diagnosis DiagnoseByMotion(const LegParams& params, const std::vector<const MeasuredData*>& records,
                           const DiagnoseOptions& opt) {
  motion::MotionFit fit(params, records, opt);
  fit.Rounds();
  fit.ConfirmTorqueNamed();
  fit.HeldOutGate();
  fit.TorqueTwinFloor();
  fit.Intervals();
  fit.ScoreTwins();
  fit.ListTorqueOnly();
  fit.ScoreTorqueFitTwin();
  fit.FindUnexplained();
  Diagnosis D = fit.Finish();
  // Stage 6c: the torque residual of the motion fit's extended twin on the held-out rows, filtered as
  // the torque fit's at its cutoff (diagnose.h Diagnosis::table_model).
  if (opt.assess) D.table_model = torque_fit::AssessModelOnRecords(params, D.extended, records, D.cutoff, opt);
  D.final_model = D.table_model;  // the motion fit searches no terms beyond the table
  return D;
}

}  // namespace exotwin
