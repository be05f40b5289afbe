#include "identification/table5.h"

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <utility>

#include "core/error.h"
#include "model/leg_dynamics.h"
#include "sim/anthropometry.h"
#include "sim/paper_tables.h"
#include "formats/number_text.h"

namespace exotwin {

namespace {

// The paper's Table 5 row of a subject, or nullptr (a subject outside S1..S10).
const Table5Row* PaperRow(const std::string& subject) {
  for (const Table5Row& r : PaperTable5())
    if (subject == r.subject) return &r;
  return nullptr;
}

// Paper values in the entry's layout: hip {id, deleva, dempster}, knee {...}.
bool PaperEntry(const std::string& subject, Table5JointRmse* hip, Table5JointRmse* knee) {
  const Table5Row* r = PaperRow(subject);
  if (!r) return false;
  *hip = {r->hip_identified, r->hip_deleva, r->hip_dempster};
  *knee = {r->knee_identified, r->knee_deleva, r->knee_dempster};
  return true;
}

std::string Cell(double v, const char* f = "%.2f") { return std::isfinite(v) ? FormatNumber(f, v) : "-"; }

// Relative error (%) of a J or X, absolute error of a Y (kg m), as "est (err)".
std::string Compare(double est, double truth, bool absolute) {
  if (absolute) return FormatNumber("%.3f", est) + " (" + FormatNumber("%+.3f", est - truth) + ")";
  return FormatNumber("%.3f", est) + " (" + FormatNumber("%+.2f", 100.0 * (est - truth) / truth) + " %)";
}

std::string ParamTable(const std::vector<Table5Entry>& entries, bool human) {
  std::string s = "| subject | J1 | J2 | X1 | X2 | Y1 | Y2 |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const Table5Entry& e : entries) {
    const LumpedParams& t = human ? *e.truth.human : e.truth.exo;
    const LumpedParams& i = human ? *e.identified.human : e.identified.exo;
    s += "| " + e.subject + " truth | " + FormatNumber("%.2f", t.J1) + " | " + FormatNumber("%.2f", t.J2) + " | " + FormatNumber("%.2f", t.X1) +
         " | " + FormatNumber("%.2f", t.X2) + " | " + FormatNumber("%.2f", t.Y1) + " | " + FormatNumber("%.2f", t.Y2) + " |\n";
    s += "| " + e.subject + " identified | " + Compare(i.J1, t.J1, false) + " | " + Compare(i.J2, t.J2, false) +
         " | " + Compare(i.X1, t.X1, false) + " | " + Compare(i.X2, t.X2, false) + " | " +
         Compare(i.Y1, t.Y1, true) + " | " + Compare(i.Y2, t.Y2, true) + " |\n";
  }
  return s;
}

// Worst |relative error| (%) of J and X, and worst |error| of Y (kg m), over the entries.
void WorstErrors(const std::vector<Table5Entry>& entries, bool human, double* jx_pct, double* y_abs) {
  *jx_pct = 0;
  *y_abs = 0;
  for (const Table5Entry& e : entries) {
    const LumpedParams& t = human ? *e.truth.human : e.truth.exo;
    const LumpedParams& i = human ? *e.identified.human : e.identified.exo;
    for (auto [a, b] : {std::pair{i.J1, t.J1}, {i.J2, t.J2}, {i.X1, t.X1}, {i.X2, t.X2}})
      *jx_pct = std::max(*jx_pct, 100.0 * std::abs(a - b) / std::abs(b));
    *y_abs = std::max({*y_abs, std::abs(i.Y1 - t.Y1), std::abs(i.Y2 - t.Y2)});
  }
}

}  // namespace

std::pair<double, double> GaitTorqueRmse(const MeasuredData& gait, const LegParams& params, double t_from,
                                         double t_to) {
  const Kinematics kin = DeriveKinematics(gait);
  double s2[2] = {0, 0};
  size_t n = 0;
  for (size_t i = 0; i < kin.t.size(); ++i) {
    if (kin.t[i] < t_from || kin.t[i] > t_to) continue;
    const Vec2 tau_R = ActuatorTorque(params, {kin.q[0][i], kin.q[1][i]}, {kin.qd[0][i], kin.qd[1][i]},
                                      {kin.qdd[0][i], kin.qdd[1][i]});
    const double e_hip = gait.tau_hip()[i] - (-tau_R[0]);  // tau_S = -tau_R, HJ15 eq. 8
    const double e_knee = gait.tau_knee()[i] - (-tau_R[1]);
    s2[0] += e_hip * e_hip;
    s2[1] += e_knee * e_knee;
    ++n;
  }
  if (n == 0) throw InputError(gait.source + ": no sample in t = " + FormatNumber("%.3f", t_from) + " .. " + FormatNumber("%.3f", t_to) + " s");
  return {std::sqrt(s2[0] / n), std::sqrt(s2[1] / n)};
}

std::vector<LegParams> Table5ParameterSets(const LegParams& identified, double weight, double L2) {
  std::vector<LegParams> sets(3, identified);
  sets[1].human = Table4AnthropometricLumped(AnthropometricModel::kDeLeva, weight, identified.L1, L2);
  sets[2].human = Table4AnthropometricLumped(AnthropometricModel::kDempster, weight, identified.L1, L2);
  for (LegParams& p : sets) {
    p.passive = PassiveModel::kRiener1999;
    p.effects.clear();
  }
  return sets;
}

void ComputeTable5Rmse(const MeasuredData& gait, double t_from, double t_to, double weight, double L2,
                       Table5Entry* entry) {
  const std::vector<LegParams> sets = Table5ParameterSets(entry->identified, weight, L2);
  double* hip[3] = {&entry->hip.identified, &entry->hip.deleva, &entry->hip.dempster};
  double* knee[3] = {&entry->knee.identified, &entry->knee.deleva, &entry->knee.dempster};
  for (int k = 0; k < 3; ++k) {
    const auto r = GaitTorqueRmse(gait, sets[k], t_from, t_to);
    *hip[k] = r.first;
    *knee[k] = r.second;
  }
  size_t n = 0;
  for (double t : gait.t()) n += t >= t_from && t <= t_to;
  entry->gait_samples = static_cast<double>(n);
}

std::string Table5Markdown(const std::vector<Table5Entry>& entries, const std::string& header) {
  std::string s = header.empty() ? "" : header + "\n\n";
  s += "## Table 5: RMS error (N m) of the predicted vs measured torque, relaxed gait at 2 km/h\n\n";
  s += "Columns: identified / De Leva / Dempster human parameters (exoskeleton identified in all three).\n\n";
  s += "Ratio: twin / paper per set.\n\n";
  s += "| subject | hip twin | hip paper | knee twin | knee paper | hip ratio | knee ratio |\n"
       "| --- | --- | --- | --- | --- | --- | --- |\n";
  auto tri = [](const Table5JointRmse& r) {
    return Cell(r.identified) + " / " + Cell(r.deleva) + " / " + Cell(r.dempster);
  };
  auto over = [](const Table5JointRmse& t, const Table5JointRmse& p) {
    return Cell(t.identified / p.identified) + " / " + Cell(t.deleva / p.deleva) + " / " + Cell(t.dempster / p.dempster);
  };
  Table5JointRmse tm[2], pm[2];  // means: twin, paper (hip, knee)
  int np = 0;
  for (const Table5Entry& e : entries) {
    Table5JointRmse ph{NAN, NAN, NAN}, pk{NAN, NAN, NAN};
    if (PaperEntry(e.subject, &ph, &pk)) {
      ++np;
      for (int j = 0; j < 2; ++j) {
        const Table5JointRmse& p = j ? pk : ph;
        pm[j].identified += p.identified;
        pm[j].deleva += p.deleva;
        pm[j].dempster += p.dempster;
      }
    }
    for (int j = 0; j < 2; ++j) {
      const Table5JointRmse& t = j ? e.knee : e.hip;
      tm[j].identified += t.identified;
      tm[j].deleva += t.deleva;
      tm[j].dempster += t.dempster;
    }
    s += "| " + e.subject + " | " + tri(e.hip) + " | " + tri(ph) + " | " + tri(e.knee) + " | " + tri(pk) + " | " +
         over(e.hip, ph) + " | " + over(e.knee, pk) + " |\n";
  }
  const double nt = static_cast<double>(entries.size());
  for (int j = 0; j < 2; ++j) {
    for (double* v : {&tm[j].identified, &tm[j].deleva, &tm[j].dempster}) *v /= nt;
    for (double* v : {&pm[j].identified, &pm[j].deleva, &pm[j].dempster}) *v = np ? *v / np : NAN;
  }
  s += "| mean | " + tri(tm[0]) + " | " + tri(pm[0]) + " | " + tri(tm[1]) + " | " + tri(pm[1]) + " | " +
       over(tm[0], pm[0]) + " | " + over(tm[1], pm[1]) + " |\n";
  auto ratio = [](const Table5JointRmse& r) {
    return Cell(r.deleva / r.identified, "%.2f") + " / " + Cell(r.dempster / r.identified, "%.2f");
  };
  s += "\nMean ratio anthropometric / identified (De Leva / Dempster):\n\n";
  s += "| joint | twin | paper |\n| --- | --- | --- |\n";
  s += "| hip | " + ratio(tm[0]) + " | " + ratio(pm[0]) + " |\n";
  s += "| knee | " + ratio(tm[1]) + " | " + ratio(pm[1]) + " |\n";
  if (np != static_cast<int>(entries.size()))
    s += "\n(paper means over the " + std::to_string(np) + " subjects shown that are in the paper)\n";

  double jx, y;
  s += "\n## Table 3: exoskeleton identified (steps 1-2) vs the twin's truth (the paper's Table 3)\n\n";
  s += "J in kg m^2, X and Y in kg m; (relative error for J and X, absolute error for Y).\n\n";
  s += ParamTable(entries, false);
  WorstErrors(entries, false, &jx, &y);
  s += "\nWorst: J, X " + FormatNumber("%.2f", jx) + " %, Y " + FormatNumber("%.4f", y) + " kg m.\n";
  s += "\n## Table 4: human identified (steps 3-4) vs the twin's truth (the paper's Table 4)\n\n";
  s += ParamTable(entries, true);
  WorstErrors(entries, true, &jx, &y);
  s += "\nWorst: J, X " + FormatNumber("%.2f", jx) + " %, Y " + FormatNumber("%.4f", y) + " kg m.\n";
  return s;
}

std::string Table5Csv(const std::vector<Table5Entry>& entries) {
  std::string s =
      "subject,twin_hip_identified,twin_hip_deleva,twin_hip_dempster,twin_knee_identified,twin_knee_deleva,"
      "twin_knee_dempster,paper_hip_identified,paper_hip_deleva,paper_hip_dempster,paper_knee_identified,"
      "paper_knee_deleva,paper_knee_dempster\n";
  for (const Table5Entry& e : entries) {
    Table5JointRmse ph{NAN, NAN, NAN}, pk{NAN, NAN, NAN};
    PaperEntry(e.subject, &ph, &pk);
    s += e.subject;
    for (const Table5JointRmse* r : {&e.hip, &e.knee, static_cast<const Table5JointRmse*>(&ph), static_cast<const Table5JointRmse*>(&pk)})
      for (double v : {r->identified, r->deleva, r->dempster}) s += "," + (std::isfinite(v) ? FormatNumber("%.4f", v) : "");
    s += "\n";
  }
  return s;
}

}  // namespace exotwin
