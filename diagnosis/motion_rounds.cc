// The motion fit's rounds (motion_fit.h "Method", steps 2-5): linearize at the current values, screen
// the candidates on the plant, select on the linear model, refine the chosen set on the plant; after
// the last round the exchanges, the elimination on the plant and the torque fit's effects put to the plant.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/parallel_for.h"
#include "diagnosis/motion_fit_internal.h"
#include "formats/number_text.h"

namespace exotwin {
namespace motion {

void MotionFit::Rounds() {
  for (int round = 0; round < kMotionOuterSteps; ++round) {
    Eigen::MatrixXd J = JacobianAtTheta();
    std::vector<ColumnBank> banks;
    Grams g;
    Linearize(J, &banks, &g);
    Screen(&J, &banks, &g);
    J = Eigen::MatrixXd();  // the banks hold the linear model from here (a long record's memory)
    Fit lin;
    SelectionTrace trace;
    chosen = SelectEffects(banks[0], g, P.scale(), opt.max_effects, loo, &lin, &trace);
    for (const auto& s : trace.steps)
      D.selection.push_back("round " + std::to_string(round + 1) + " (linearized at " + Labels(P, previous) + "): " + s);
    g_last = std::move(g);
    if (chosen.empty()) {
      theta = zero, at = given;
      break;
    }
    if (!RefineChosen(round, banks[0], lin)) break;
    std::vector<int> key = chosen;
    std::sort(key.begin(), key.end());
    const bool repeated = std::find(seen.begin(), seen.end(), key) != seen.end();
    std::vector<int> last_key = previous;
    std::sort(last_key.begin(), last_key.end());
    const bool converged = repeated && rounds.size() >= 2 && last_key == key;
    if (!repeated) seen.push_back(key);
    previous = chosen;
    if (!repeated && round + 1 < kMotionOuterSteps) continue;
    // The last round's set and, where the rounds did not converge, the best round's, each taken
    // through the exchanges, the friction's form and the elimination; the lower exact BIC stays.
    Polish(banks[0], round);
    const std::vector<int> last_set = chosen;
    const Eigen::VectorXd last_theta = theta;
    const double last_bic = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    if (!KeepBestRound(converged)) break;
    Polish(banks[0], round);
    const double best_bic = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    if (!(last_bic < best_bic)) break;
    MotionProblem::Rollout rl = P.Simulate(last_theta, Part::kBoth);
    if (!rl.ok) break;
    D.selection.push_back("round " + std::to_string(round + 1) + ": the last round's set, after the same, " +
                          Labels(P, last_set) + " kept: exact BIC " + NumberText(last_bic, 4) + " against " +
                          NumberText(best_bic, 4));
    chosen = last_set, theta = last_theta, at = std::move(rl);
    break;
  }
}

Eigen::MatrixXd MotionFit::JacobianAtTheta() {
  Eigen::MatrixXd J = P.Jacobian(theta, at, all, Part::kBoth);
  tau_eff = ResidualAutocorrelation(P, at, window_rows);
  // The one-parameter effects of the current set: secants from the set without them.
  std::vector<int> in_set;
  std::vector<Eigen::VectorXd> without;
  for (int c : chosen)
    if (cands[static_cast<size_t>(c)].cols.size() == 1 && theta[cands[static_cast<size_t>(c)].cols[0]] != 0) {
      in_set.push_back(cands[static_cast<size_t>(c)].cols[0]);
      without.push_back(theta);
      without.back()[in_set.back()] = 0;
    }
  const std::vector<MotionProblem::Rollout> ro_without = P.SimulateAll(without, Part::kBoth);
  for (size_t k = 0; k < in_set.size(); ++k)
    if (ro_without[k].ok) Secant(&J, in_set[k], ro_without[k], -(theta[in_set[k]]));
  Charge(kJacobians);
  return J;
}

void MotionFit::Linearize(const Eigen::MatrixXd& J, std::vector<ColumnBank>* banks_out, Grams* g_out) {
  banks_out->clear();  // a relinearization's old banks (as large as J) gone before the new ones
  std::vector<ColumnBank> banks(P.records());
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    ColumnBank& b = banks[r];
    const size_t m = P.rows(r).size();
    const Eigen::Index m2 = static_cast<Eigen::Index>(2 * m);
    b.sample = P.rows(r);
    b.train.resize(m);
    for (size_t k = 0; k < m; ++k) b.train[k] = k < P.fit_rows(r);
    b.X = wv.segment(off, m2).asDiagonal() * J.middleRows(off, m2);
    b.r = wv.segment(off, m2).asDiagonal() * (P.measured(r) - at.q[r] + J.middleRows(off, m2) * theta);
    b.candidates = cands;
    b.used = n_par;
    b.n = records[r]->size();
    off += m2;
  }
  Grams g = MakeGrams(banks);
  g.n_eff = g.n_tr / tau_eff;
  g.scale_name = "measured angle";
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
    for (int j = 0; j < 2; ++j) {
      std::vector<double> q;
      for (size_t k = mf; k < m; ++k) q.push_back(P.measured(r)[static_cast<Eigen::Index>(j * m + k)]);
      const double s = RmsAboutMean(q) * P.weight(r, j);
      g.tt_te[j] += s * s * static_cast<double>(q.size());
    }
  }
  *banks_out = std::move(banks);
  *g_out = std::move(g);
}

void MotionFit::Secant(Eigen::MatrixXd* J, int k, const MotionProblem::Rollout& rx, double dx) {
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    J->col(k).segment(off, rx.q[r].size()) = (rx.q[r] - at.q[r]) / dx;
    off += rx.q[r].size();
  }
}

// Screening (motion_fit.h step 3): every one-parameter candidate whose linear fit on top of the
// current set is significant and lowers the BIC is refined alone on the plant (LM, the set held);
// its column becomes the secant to that value, so the selection sees its exact single fit.
void MotionFit::Screen(Eigen::MatrixXd* J_io, std::vector<ColumnBank>* banks_io, Grams* g_io) {
  Eigen::MatrixXd& J = *J_io;
  std::vector<ColumnBank>& banks = *banks_io;
  Grams& g = *g_io;
  const Fit f_set = FitCols(g, ColumnsOf(banks[0], chosen), false);
  std::vector<int> screen;
  std::vector<Eigen::VectorXd> start;
  for (size_t c = 0; c < cands.size(); ++c) {
    const Candidate& cand = cands[c];
    if (cand.cols.size() != 1 || std::find(chosen.begin(), chosen.end(), static_cast<int>(c)) != chosen.end()) continue;
    std::vector<int> set = chosen;
    set.push_back(static_cast<int>(c));
    const Fit f = FitCols(g, ColumnsOf(banks[0], set), false);
    const int k = cand.cols[0];
    if (!f.ok || !(f.bic < f_set.bic) || !(std::abs(CoefOf(f, k)) > kMinT * SeOf(f, k))) continue;
    Eigen::VectorXd x = theta;
    x[k] = std::clamp(CoefOf(f, k), P.lower(k), P.upper(k));
    if (x[k] == theta[k]) continue;
    screen.push_back(k);
    start.push_back(x);
  }
  std::vector<double> refined(screen.size());
  std::vector<MotionProblem::Rollout> at_refined(screen.size());
  ParallelFor(screen.size(), DiagnoseThreads(opt), [&](size_t i) {
    const int k = screen[i];
    refined[i] = RefineOne(P, k, theta, at, start[i][k], kMotionScreenIterations);
    if (refined[i] == theta[k]) return;
    Eigen::VectorXd x = theta;
    x[k] = refined[i];
    at_refined[i] = P.Simulate(x, Part::kBoth);
  });
  for (size_t i = 0; i < screen.size(); ++i)
    if (at_refined[i].ok) Secant(&J, screen[i], at_refined[i], refined[i] - theta[screen[i]]);
  if (!screen.empty()) Linearize(J, &banks, &g);
  Charge(kScreening);
}

bool MotionFit::RefineChosen(int round, const ColumnBank& bank, const Fit& lin) {
  const std::vector<int> cols = ColumnsOf(bank, chosen);
  Eigen::VectorXd start_lin = zero, start_torque = zero;
  for (size_t k = 0; k < lin.cols.size(); ++k) start_lin[lin.cols[k]] = lin.coef[static_cast<Eigen::Index>(k)];
  start_torque = start_lin;
  const bool has_torque = TorqueValuesOfSet(P, T.effects, chosen, &start_torque);
  std::vector<Eigen::VectorXd> starts = {start_lin};
  if (has_torque) starts.push_back(start_torque);
  Refined rf = Refine(P, cols, starts, kMotionLmIterations, false);
  if (!std::isfinite(rf.cost)) {
    // Neither start simulates (e.g. a strap's linear value too stiff for the step): from the current
    // values (the set's new effects at 0), which do.
    Eigen::VectorXd from_theta = zero;
    for (int k : cols) from_theta[k] = theta[k];
    rf = Refine(P, cols, {from_theta}, kMotionLmIterations, false);
  }
  if (!std::isfinite(rf.cost)) {
    D.selection.push_back("round " + std::to_string(round + 1) + ": " + Labels(P, chosen) +
                          " cannot be simulated at its fitted values; " +
                          (previous.empty() ? "nothing named" : "the last round's set kept"));
    chosen = previous;
    if (chosen.empty()) theta = zero, at = given;
    return false;
  }
  theta = rf.theta;
  at = P.Simulate(theta, Part::kBoth);
  Charge(kRefinement);
  rounds.push_back({chosen, theta, rf.cost});
  std::ostringstream os;
  os << "round " << round + 1 << ": refined on the plant:";
  for (int c : chosen) {
    const Candidate& cand = cands[static_cast<size_t>(c)];
    os << " " << cand.Label() << " = " << ValueText(P, cand, theta);
  }
  D.selection.push_back(os.str());
  return true;
}

void MotionFit::Polish(const ColumnBank& bank, int round) {
  ExchangeEffects(bank, g_last, round);
  ExchangeFrictionForm(round);
  EliminateOnThePlant(round);
}

bool MotionFit::KeepBestRound(bool converged) {
  size_t best = rounds.size() - 1;
  for (size_t k = 0; !converged && k < rounds.size(); ++k)
    if (ExactBic(rounds[k].cost, ParameterCount(rounds[k].set)) <
        ExactBic(rounds[best].cost, ParameterCount(rounds[best].set)))
      best = k;
  if (best + 1 != rounds.size()) {
    MotionProblem::Rollout rb = P.Simulate(rounds[best].theta, Part::kBoth);
    if (rb.ok) {
      D.selection.push_back("round " + std::to_string(best + 1) + "'s set " + Labels(P, rounds[best].set) +
                            " kept: exact BIC " +
                            NumberText(ExactBic(rounds[best].cost, ParameterCount(rounds[best].set)), 4) +
                            ", the last round's " + Labels(P, rounds.back().set) + " " +
                            NumberText(ExactBic(rounds.back().cost, ParameterCount(chosen)), 4));
      chosen = rounds[best].set, theta = rounds[best].theta, at = std::move(rb);
      return true;
    }
  }
  return false;
}

double MotionFit::ExactBic(double cost, size_t k) const {
  const double n_eff = g_last.n_eff > 0 ? g_last.n_eff : 1.0, n_tr = std::max(g_last.n_tr, 1.0);
  return n_eff * std::log(cost / n_tr) + static_cast<double>(k) * std::log(n_eff);
}

size_t MotionFit::ParameterCount(const std::vector<int>& set) const {
  size_t k = 0;
  for (int c : set) k += cands[static_cast<size_t>(c)].cols.size();
  return k;
}

// The exchanges of motion_fit.h step 5: a chosen effect replaced by a candidate, or by two while the
// set is below max_effects, where the linear model of this round (bank, g) ranks the swap lowest in BIC and the exact plant confirms it (the
// swapped set refined from the set's values, the effect taken out, and from the linear fit's: its
// fit-part BIC lower); kMotionExchanges at most.
// Forward selection with backward elimination misses a swap when an effect entered early stands in
// for one that only pays once others are in (a knee joint_stiffness for a strap, issue 41).
void MotionFit::ExchangeEffects(const ColumnBank& bank, const Grams& g, int round) {
  for (int ex = 0; ex < kMotionExchanges; ++ex) {
    const Fit cur = FitCols(g, ColumnsOf(bank, chosen), false);
    if (!cur.ok) break;
    double best_bic = cur.bic;
    std::vector<int> best_set;
    Fit best_fit;
    auto consider = [&](const std::vector<int>& set) {
      for (size_t a = 0; a < set.size(); ++a)
        for (size_t b = a + 1; b < set.size(); ++b)
          if (set[a] == set[b] || Conflicts(cands[static_cast<size_t>(set[a])], cands[static_cast<size_t>(set[b])])) return;
      const Fit f = FitCols(g, ColumnsOf(bank, set), false);
      if (f.ok && f.bic < best_bic) best_bic = f.bic, best_set = set, best_fit = f;
    };
    const bool pairs = static_cast<int>(chosen.size()) < opt.max_effects;
    for (size_t i = 0; i < chosen.size(); ++i)
      for (size_t c = 0; c < cands.size(); ++c) {
        if (std::find(chosen.begin(), chosen.end(), static_cast<int>(c)) != chosen.end()) continue;
        std::vector<int> set = chosen;
        set[i] = static_cast<int>(c);
        consider(set);
        // One effect for two: a stand-in that took the share of two effects leaves neither of them
        // material on its own (a hip gravity error for a hip dead band and Coulomb friction).
        for (size_t d = c + 1; pairs && d < cands.size(); ++d) {
          if (std::find(chosen.begin(), chosen.end(), static_cast<int>(d)) != chosen.end()) continue;
          std::vector<int> two = set;
          two.push_back(static_cast<int>(d));
          consider(two);
        }
      }
    if (best_set.empty()) break;
    Eigen::VectorXd kept = theta, lin = theta;
    for (int c : chosen)
      if (std::find(best_set.begin(), best_set.end(), c) == best_set.end())
        for (int k : cands[static_cast<size_t>(c)].cols) kept[k] = lin[k] = 0;
    for (size_t k = 0; k < best_fit.cols.size(); ++k)
      lin[best_fit.cols[k]] =
          std::clamp(best_fit.coef[static_cast<Eigen::Index>(k)], P.lower(best_fit.cols[k]), P.upper(best_fit.cols[k]));
    const Refined rf = Refine(P, ColumnsOf(cand_bank, best_set), {lin, kept}, kMotionLmIterations, false);
    if (!std::isfinite(rf.cost)) break;
    const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    const double bic_x = ExactBic(rf.cost, ParameterCount(best_set));
    const bool better = bic_x < bic_now;
    D.selection.push_back("round " + std::to_string(round + 1) + ": exchange " + Labels(P, chosen) + " -> " +
                          Labels(P, best_set) + ": exact BIC " + NumberText(bic_now, 4) + " -> " +
                          NumberText(bic_x, 4) + (better ? ", taken" : ", not taken"));
    if (!better) break;
    MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);  // both parts, for what follows
    if (!rx.ok) break;
    chosen = best_set, theta = rf.theta, at = std::move(rx);
  }
}

// Backward elimination on the exact plant (motion_fit.h step 5, after the exchanges): each chosen
// effect taken out and the rest refined from the set's values (step 4's refinement, the effect at 0);
// the removal of the lowest exact fit-part BIC taken where that BIC is below the set's or where what
// the effect adds at its joint on the fit parts is below the selection's materiality (an exchange
// does not check it), repeated. The
// linear model's elimination (SelectEffects) judges a stand-in where it entered; once an exchange or
// the friction's form brought in what it stood for (a hip dead band for the sensor gains that took its
// knocks), only the plant shows that it adds nothing.
void MotionFit::EliminateOnThePlant(int round) {
  // The materiality floor per joint on the fit parts (the selection's, SelectEffects): kMinTorqueShare
  // of the measured angle's RMS about its mean, squared, times the rows, in the weighted SSE.
  double floor[2] = {0, 0};
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
    for (int j = 0; j < 2; ++j) {
      std::vector<double> q;
      for (size_t k = 0; k < mf; ++k) q.push_back(P.measured(r)[static_cast<Eigen::Index>(j * m + k)]);
      const double s = kMinTorqueShare * RmsAboutMean(q) * P.weight(r, j);
      floor[j] += s * s * static_cast<double>(q.size());
    }
  }
  while (chosen.size() > 1) {
    const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    double sse_now[2];
    P.Sse(at, Part::kFit, sse_now);
    std::vector<std::vector<int>> sets;
    std::vector<Eigen::VectorXd> refined;
    std::vector<double> bics;
    for (size_t i = 0; i < chosen.size(); ++i) {
      std::vector<int> set = chosen;
      set.erase(set.begin() + static_cast<long>(i));
      Eigen::VectorXd x = theta;
      for (int k : cands[static_cast<size_t>(chosen[i])].cols) x[k] = 0;
      const Refined rf = Refine(P, ColumnsOf(cand_bank, set), {x}, kMotionLmIterations, false);
      if (!std::isfinite(rf.cost)) continue;
      sets.push_back(set), refined.push_back(rf.theta), bics.push_back(ExactBic(rf.cost, ParameterCount(set)));
    }
    // Taken out where the BIC is lower without it, or where what it adds at its joint is immaterial.
    const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(refined, Part::kFit);
    int best = -1;
    std::string why;
    for (size_t s = 0; s < sets.size(); ++s) {
      int out = -1;
      for (int c : chosen)
        if (std::find(sets[s].begin(), sets[s].end(), c) == sets[s].end()) out = c;
      const int j = cands[static_cast<size_t>(out)].joint;
      double sse[2] = {INFINITY, INFINITY};
      if (ro[s].ok) P.Sse(ro[s], Part::kFit, sse);
      const bool lower = bics[s] < bic_now, immaterial = sse[j] - sse_now[j] < floor[j];
      if ((lower || immaterial) && (best < 0 || bics[s] < bics[static_cast<size_t>(best)])) {
        best = static_cast<int>(s);
        why = lower ? "" : " (higher, but what " + cands[static_cast<size_t>(out)].Label() +
                               " adds at its joint is below the materiality of " + NumberText(100 * kMinTorqueShare) +
                               " % of the measured angle's RMS)";
      }
    }
    if (best < 0) break;
    MotionProblem::Rollout rx = P.Simulate(refined[static_cast<size_t>(best)], Part::kBoth);
    if (!rx.ok) break;
    D.selection.push_back("round " + std::to_string(round + 1) + ": on the plant " + Labels(P, chosen) + " -> " +
                          Labels(P, sets[static_cast<size_t>(best)]) + ": exact BIC " + NumberText(bic_now, 4) + " -> " +
                          NumberText(bics[static_cast<size_t>(best)], 4) + why + ", taken");
    chosen = sets[static_cast<size_t>(best)], theta = refined[static_cast<size_t>(best)], at = std::move(rx);
  }
  Charge(kRefinement);
}

// The torque fit's effects put to the plant (motion_fit.h step 5): each effect the torque fit names
// that is a candidate and not chosen, added to the set at the torque fit's value (fitted on the
// same fit parts), is tried further where it lowers the held-out simulated error at its joint by
// kMinHeldoutGain; then refined with the set from there, taken where the exact fit-part BIC is
// lower. One that conflicts with a chosen effect (Conflicts: the other gravity axis, a shared
// offset) is not tried. The torque residual has weighed it already (the BIC margin, held-out gains,
// |t|); the plant has to agree, not to find it again: where the fit part barely moves a joint, its
// friction shows in the torque but only weakly in 0.5 s windows of simulated motion. A torque fit's
// stand-in for an effect the torque cannot see (a ripple for a dead band) moves the held-out motion
// away and is not refined.
void MotionFit::ConfirmTorqueNamed() {
  auto eligible = [&](int c) {
    return c >= 0 && std::none_of(chosen.begin(), chosen.end(), [&](int s) {
             return Conflicts(cands[static_cast<size_t>(s)], cands[static_cast<size_t>(c)]);
           });
  };
  // Each effect's trial at the current values; all remaining ones simulated together (in parallel)
  // whenever the set changes.
  std::vector<int> cand_of(T.effects.size(), -1);
  std::vector<Eigen::VectorXd> trial(T.effects.size());
  std::vector<MotionProblem::Rollout> trial_ro(T.effects.size());
  std::vector<char> simulated(T.effects.size(), 0);
  for (size_t e = 0; e < T.effects.size(); ++e) {
    const Effect& fx = T.effects[e].effect;
    cand_of[e] = CandidateOf(P, fx);
  }
  for (size_t e = 0; e < T.effects.size(); ++e) {
    const int c = cand_of[e];
    if (!eligible(c)) continue;
    if (!simulated[e]) {
      std::vector<size_t> batch;
      std::vector<Eigen::VectorXd> xs;
      for (size_t f = e; f < T.effects.size(); ++f) {
        if (!eligible(cand_of[f])) continue;
        Eigen::VectorXd x = theta;
        if (!TorqueValues(P, T.effects[f].effect, &x)) continue;
        for (int k : cands[static_cast<size_t>(cand_of[f])].cols) x[k] = std::clamp(x[k], P.lower(k), P.upper(k));
        trial[f] = x;
        batch.push_back(f);
        xs.push_back(x);
      }
      const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(xs, Part::kHeldOut);
      for (size_t b = 0; b < batch.size(); ++b) trial_ro[batch[b]] = ro[b], simulated[batch[b]] = 1;
      if (!simulated[e]) continue;  // TorqueValues: no candidate value stands for it
    }
    const Candidate& cand = cands[static_cast<size_t>(c)];
    const Eigen::VectorXd& x = trial[e];
    std::string text = "the torque fit's " + cand.Label() + " = " + ValueText(P, cand, x) + " added to " +
                       Labels(P, chosen) + ": ";
    if (!trial_ro[e].ok) {
      D.selection.push_back(text + "the plant cannot simulate it, not taken");
      continue;
    }
    double te_now[2], te_x[2];
    P.Sse(at, Part::kHeldOut, te_now);
    P.Sse(trial_ro[e], Part::kHeldOut, te_x);
    const double gain = te_now[cand.joint] > 0 ? 1 - te_x[cand.joint] / te_now[cand.joint] : 0.0;
    text += "held-out simulated error at the " + std::string(kJoint[cand.joint]) + " " + NumberText(-100 * gain, 3) + " %";
    if (!(gain >= kMinHeldoutGain)) {
      D.selection.push_back(text + " (needed -" + NumberText(100 * kMinHeldoutGain) + " %), not taken");
      continue;
    }
    std::vector<int> set = chosen;
    set.push_back(c);
    const Refined rf = Refine(P, ColumnsOf(cand_bank, set), {x}, kMotionLmIterations, false);
    if (!std::isfinite(rf.cost)) continue;
    const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    const double bic_x = ExactBic(rf.cost, ParameterCount(set));
    const bool better = bic_x < bic_now;
    D.selection.push_back(text + "; refined, exact BIC " + NumberText(bic_now, 4) + " -> " + NumberText(bic_x, 4) +
                          (better ? ", taken" : ", not taken"));
    if (!better) continue;
    MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);
    if (!rx.ok) continue;
    chosen = set, theta = rf.theta, at = std::move(rx);
    std::fill(simulated.begin(), simulated.end(), 0);  // the trials of the rest, at the new values
  }
  Charge(kRefinement);
}

}  // namespace motion
}  // namespace exotwin
