// The discrepancy loop of the EMG-driven joint-torque model (issue 19; emg-fit --report): starting
// from the linear form of HJ15 eq. 26-27, candidate causes of what it misses are added one at a time,
// only when they generalize, with the gates of diagnose's selection (diagnose_select.h):
//  - the Bayesian information criterion (effective sample size from the residual autocorrelation,
//    every searched parameter counted) drops by more than kBicMargin;
//  - the cross-validated error drops by at least kMinHeldoutGain at a joint the cause acts on, and
//    in sum over both joints: with several recordings, each recording is left out in turn and
//    predicted by the fit on the others, and every one of them must gain; with one recording, its
//    `blocks` contiguous blocks are left out in turn (scores over samples within kSpikeMads of the
//    median moment). The last 30 % of every recording is scored too, for comparison only;
//  - the cause's parameter is significant (|t| > kMinT: coefficients by least squares, searched
//    parameters by the profile of the sum of squares) and inside its physiological range (a cause
//    outside it is listed with its verdict, not named).
// Among the admissible causes the one with the lowest BIC is added; the searched parameters are then
// refined together, on the first 70 % of every recording (the BIC's rows).
// Candidates (emg_torque_model.h): one electromechanical delay common to every channel (searched on
// 0-200 ms, named within 10-100 ms), the muscle twitch common to every channel (searched on 10-150
// ms, named within 20-100 ms), the two together (searched inside their ranges), then (fewer
// parameters first) a muscle's own delay once a common one is named (within 10-100 ms), the A-shape
// activation nonlinearity (-3 < A < 0), angle-dependent moment arms per joint (keeping their sign,
// changing by at most a factor 3 over the calibrated angles), the passive moment per joint (scale in
// (0, 3]), the vasti standing in for a missing gluteus maximus at the hip.
// Signs: after the papers' linear form (alphas free of sign) every alpha is fitted with its muscle's
// sign (EmgModelSpec::signed_alphas; a muscle only pulls); when the loop stops with alphas held at
// zero, freeing the signs is judged by the same gates, else the held alphas are reported (not
// separable at their joint, with the value they take free of sign). Channels of one muscle one of
// which is held (or against the muscle's action) are then pooled when that keeps the sign and costs
// at most kParsimony of the cross-validated error, else reported not separable. The robust handling of contact spikes (fit rows beyond kSpikeMads left out) is
// decided first, because it changes the rows every other cause is fitted on; it must pay on the
// cross-validation like the others.
#pragma once
#include <string>
#include <vector>

#include "emg/emg_torque_model.h"

namespace exotwin {

// What of a measured joint moment lies beyond the band an EMG-driven estimate occupies. The
// estimate is made of envelopes (low-passed) through the muscle twitch and of the angles, so it has
// almost no content above some frequency; what the measured moment has there (inverse dynamics'
// noise and impact transients, Bisseling & Hof 2006, J Biomech 39:2438-2444; Kristianslund,
// Krosshaug & van den Bogert 2012, J Biomech 45:666-671) is error for any estimate of that band,
// whatever its causes. band_hz: the lowest frequency (0.5 Hz steps) above which the estimate holds
// at most kBandResidue of its variance (zero-phase 4th-order Butterworth high-pass H, |H| <= 1);
// share_above = |H m|^2 / SST and estimate_share = |H p|^2 / SST, with m the measured moment, p the
// estimate, SST the measured variance, on the samples within kSpikeMads of the median (the scored
// ones; the samples beyond are bridged linearly before filtering), pooled over the recordings.
// Since SSE >= |H (m - p)|^2 >= (|H m| - |H p|)^2, R^2 <= r2 = 1 - (sqrt(share_above) -
// sqrt(estimate_share))^2 (1 when the estimate holds more above the band than the moment).
constexpr double kBandResidue = 0.001;
struct EmgBandCeiling {
  double band_hz = 0;
  double share_above = 0, estimate_share = 0;
  double r2 = 1;
};
// Of `model`'s estimate at `joint` on `recs` (with moments; sampled uniformly, >= 50 samples each).
EmgBandCeiling BandCeiling(const EmgTorqueModel& model, const std::vector<const EmgRecording*>& recs, int joint);

struct EmgStep {
  std::string added;  // "linear form (HJ15 eq. 26)" for the first step
  std::string why;    // the gates' figures, in words
  EmgTorqueModel model;  // fitted on the first 70 % (figures, held-out scores)
};

struct EmgCandidateScore {
  int round = 0;
  std::string label;
  double delta_bic = 0;
  double gain_pct[2] = {0, 0};     // last-30 % held-out SSE drop per joint, % (for comparison)
  double cv_gain_pct[2] = {0, 0};  // cross-validated SSE drop per joint, % (the gate)
  bool added = false;
  std::string verdict;  // why it was or was not added
};

struct EmgDiagnosis {
  std::vector<EmgStep> steps;              // [0] the linear form, then one per added cause
  std::vector<EmgCandidateScore> scores;   // every candidate of every round
  std::vector<std::string> selection;      // the loop's steps in words
  EmgTorqueModel calibration;              // the final structure fitted on every sample of every recording
  double holdout_fraction = 0.3;
  bool folds_are_recordings = false;  // several recordings: each left out in turn; else blocks
  int folds = 0;
  std::vector<std::string> sources, notes, missing;
  // First recording, for plots: time, measured and estimated moments (linear, final) on all samples
  // (the held-out part starts at `split`), estimated by the fits on the first 70 %.
  std::vector<double> t, measured[2], linear[2], final_[2];
  size_t split = 0;
  EmgBandCeiling ceiling[2];  // of the calibration (BandCeiling)
  EmgRecording first_recording;  // for the musculoskeletal form's muscle plots (report)
};

struct EmgDiagnoseOptions {
  double holdout_fraction = 0.3;
  int max_steps = 10;
  bool robust_candidate = true;  // consider the robust fit
  bool signed_alphas = true;     // fit every alpha with its muscle's sign (EmgModelSpec::signed_alphas)
  int blocks = 5;                // one recording: contiguous cross-validation blocks (>= 2)
  // Calibrate the musculoskeletal form (emg_msk_model.h) too and choose it at a joint where its
  // cross-validated error is lower than the linear calibration's by kMinHeldoutGain (the loop's gate).
  // Off by default (the loop alone, ~4 s less per call); emg-fit turns it on.
  bool musculoskeletal = false;
  std::map<std::string, std::array<double, 2>> strength_bounds;  // per channel (MuscleMap::strength_bounds)
};

// Runs the loop on recordings with moments (same mapped channels). Throws InputError on unusable input.
EmgDiagnosis DiagnoseEmg(const std::vector<const EmgRecording*>& recs, const EmgDiagnoseOptions& opt = {});

// diagnosis.json text (the format of `exotwin diagnose` where the concepts match: effects with value,
// unit, ci95; joints with rmse_before / rmse_after / gain_pct; validation; selection), plus steps.
std::string EmgDiagnosisJson(const EmgDiagnosis& d);
// Self-contained HTML report: steps table, candidates, plots of the held-out part.
std::string EmgDiagnosisHtml(const EmgDiagnosis& d);
// Writes DIR/diagnosis.json and DIR/report.html (creates DIR).
void WriteEmgDiagnosis(const EmgDiagnosis& d, const std::string& dir);

}  // namespace exotwin
