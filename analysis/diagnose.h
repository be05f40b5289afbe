// `exotwin diagnose` (DESIGN.md): where the twin and the measured data disagree, which effect of the
// DESIGN list explains it (with value and 95 % interval), the extended model, and the held-out gain.
//
// Method (diagnose.cc):
//  1. residual r = measured tau_S - twin tau_S (predict), per joint; white-noise level per joint from
//     the first differences of r; rows weighted by 1/noise.
//  2. candidates: every effect per joint, each as columns of a linear model of r (first order in the
//     effect, DESIGN "how it shows": sign(qd), qd, qdd, g sin/cos, [q, 1], (b/2) s(tau) dtau/dq,
//     dtau_C/dq tau_C, sin/cos(2 pi f q), 1, tau_S, -dtau_S/dt, EMG envelopes). The ripple frequency
//     is found by grid + golden search; delay, backlash and strap stiffness are refined by golden
//     search on the exact model after selection.
//  3. fit on the first 70 % in time; score every single effect and every pair by BIC (with the
//     effective sample size from the residual's autocorrelation) and by the error on the last 30 %;
//     name an effect only if BIC drops by more than kBicMargin, the held-out error drops by at least
//     5 % and its coefficient is significant (|t| > 4).
//  4. the extended twin (predict with the effects) runs on the held-out 30 %: rmse_after.
//  5. structure left in the held-out residual (low-passed rms well above the noise) is reported as
//     unexplained with its dominant frequency and its correlation with angle, velocity, accel, time.
#pragma once
#include <string>
#include <vector>

#include "analysis/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

struct DiagnosedEffect {
  Effect effect;
  double ci_lo = 0, ci_hi = 0;  // 95 % interval of effect.value
  double explained_pct = 0;     // % of the held-out residual sum of squares this effect removes
};

struct UnexplainedStructure {
  std::string joint;
  double rms = 0;                // N m, low-passed (5 Hz) held-out residual after the extension
  double dominant_hz = 0;        // peak of the residual spectrum
  double corr_q = 0, corr_qd = 0, corr_qdd = 0, corr_t = 0;  // Pearson correlation with r
  std::string hint;              // words: what it looks like
};

struct CandidateScore {
  std::string label;  // e.g. "coulomb_friction(knee)" or "a + b"
  double delta_bic = 0, heldout_gain_pct = 0;
  bool selected = false;
};

struct JointScore {
  double rmse_before = 0, rmse_after = 0, gain_pct = 0;  // on the held-out part, N m
};

struct Diagnosis {
  std::vector<DiagnosedEffect> effects;
  std::vector<UnexplainedStructure> unexplained;
  JointScore joints[2];
  double holdout_fraction = 0.3;
  std::string method;
  LegParams extended;                   // params + effects
  std::vector<CandidateScore> scores;   // singles (best first) and the best pairs, for the report
  std::vector<std::string> collinear;   // nearly collinear candidate pairs on this record, in words
  double noise[2] = {0, 0};             // white noise of the residual, N m
  double tau_eff = 1;                   // residual autocorrelation length (fit rows)
  // Series for plots (full record): measured, twin before, extended twin after; split index.
  Kinematics kin;
  std::vector<double> measured[2], before[2], after[2];
  size_t split = 0;
};

struct DiagnoseOptions {
  double holdout_fraction = 0.3;
  size_t max_fit_rows = 60000;  // per joint; longer records are strided
  int max_effects = 2;
  std::string mjcf;              // MJCF instead of the shipped model
};

// Runs the discrepancy analysis. `params` is the twin to confront, `data` the measured record
// (>= 200 samples). Throws InputError on unusable input (e.g. too short), SimulationError if the
// twin cannot be evaluated.
Diagnosis Diagnose(const LegParams& params, const MeasuredData& data, const DiagnoseOptions& opt = {});

// diagnosis.json text (DESIGN.md format plus `signature` fields in unexplained).
std::string DiagnosisJson(const Diagnosis& d);

// Writes DIR/diagnosis.json, DIR/extended.yaml and DIR/report.html (creates DIR).
void WriteDiagnosis(const Diagnosis& d, const std::string& dir, const std::string& params_path,
                    const std::string& measured_path);

}  // namespace exotwin
