// muscle_activity (DESIGN.md "Effects": the subject was not relaxed): its fit row and code. The torque
// fit's candidate at a joint has one column per EMG channel of the record, minus the channel's linear
// envelope (EmgEnvelopes), the same at both joints; its effect has value 1 and the channels' weights.
// The forward plant does not carry it (the EMG is an input of the record): no motion-fit candidate.
#include <algorithm>
#include <cmath>

#include "diagnosis/column_tools.h"
#include "diagnosis/effects.h"
#include "diagnosis/family_rows.h"

namespace exotwin {
namespace {

std::string AnyValue(const Effect&, const PhysicalScale&) { return ""; }

// Value 1, the weights of the channels whose coefficient is beyond 2 standard errors (at least the
// first channel's).
void MuscleEffect(const Candidate& c, const Fit& f, DiagnosedEffect* d) {
  Effect& e = d->effect;
  e.value = 1.0, d->ci_lo = d->ci_hi = 1.0;
  for (size_t k = 0; k < c.cols.size(); ++k)
    if (std::abs(CoefOf(f, c.cols[k])) > 2.0 * SeOf(f, c.cols[k])) e.fields["w_" + c.channels[k]] = CoefOf(f, c.cols[k]);
  if (e.fields.empty()) e.fields["w_" + c.channels[0]] = CoefOf(f, c.cols[0]);
}

bool AnyChannelSignificant(const Candidate& c, const Fit& f) {
  bool significant = false;
  for (int col : c.cols) significant |= std::abs(CoefOf(f, col)) > kMinT * SeOf(f, col);
  return significant;
}

Effect DrawMuscle(Rng& rng, int joint, bool) {
  Effect e;
  e.value = 1.0;
  const char* ch[2][2] = {{"GMAX", "RF"}, {"VM", "ST"}};
  for (const char* c : ch[joint]) e.fields[std::string("w_") + c] = rng.Sign() * rng.Uniform(3.0, 10.0);
  return e;
}

// The hip's columns from the channels' envelopes two at a time (filtered together: EmgEnvelopes), the
// pending columns placed first (the envelopes' record-long temporaries come next), their fit rows
// (filtered, unweighted) kept for the knee's columns.
void MuscleColumns(ColumnContext& x, const FitFamily& self) {
  const Kinematics& kin = x.kin;
  if (kin.emg.empty()) return;
  ColumnBank& b = x.bank;
  std::vector<int> cols;
  std::vector<std::string> chans;
  if (x.j == 0) {
    x.kept_rows.assign(kin.emg.size(), {});
    std::vector<const std::vector<double>*> emg;
    for (const auto& ch : kin.emg) emg.push_back(&ch.second), chans.push_back(ch.first);
    for (size_t c0 = 0; c0 < emg.size(); c0 += 2) {
      x.pending.Flush();
      const size_t K = std::min<size_t>(2, emg.size() - c0);
      std::vector<std::vector<double>> env =
          EmgEnvelopes(kin.t, {emg.begin() + static_cast<long>(c0), emg.begin() + static_cast<long>(c0 + K)});
      for (size_t k = 0; k < K; ++k) {
        for (double& v : env[k]) v = -v;
        cols.push_back(NewColumn(b));
        SetJointColumn(x.pending, cols.back(), x.w, 0, std::move(env[k]), &x.kept_rows[c0 + k]);
      }
    }
  } else {
    for (const auto& ch : kin.emg) {
      const int c = NewColumn(b);
      const std::vector<double>& rows = x.kept_rows[chans.size()];
      SetJointRows(b, c, x.w, x.j, [&](size_t k) { return rows[k]; });
      cols.push_back(c);
      chans.push_back(ch.first);
    }
  }
  x.AddCandidate(self, cols).channels = chans;
}

}  // namespace

FitFamily MuscleActivityRow() {
  FitFamily f = FitRow("muscle_activity", AnyValue, DrawMuscle);
  f.to_effect = MuscleEffect, f.significant = AnyChannelSignificant;
  f.add_columns = MuscleColumns;
  return f;
}

}  // namespace exotwin
