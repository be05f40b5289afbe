// EMG-driven joint torque of the hip and the knee: the linear form of Hwang & Jeon 2015 (HJ15
// HJ15 eq. 26-27, after Olney & Winter 1985) and the extensions the discrepancy loop may add
// (emg/emg_diagnose.h). Per joint j:
//
//   tau_j(t) = sum_i (alpha_i + alpha_q,i q_j) a_i(t) + beta q_j + gamma qd_j + offset + s_P M_P,j(q)
//   a_i(t)   = ((e^{A u} - 1) / (e^A - 1))  with u = T_tau[e_i](t - d_m)  (A = 0: a = u)
//   T_tau    : the muscle twitch, a critically damped second-order low-pass of unit gain and time
//              constant tau (impulse response t/tau^2 e^{-t/tau}, peak at t = tau), causal; tau = 0:
//              none. The twitch filter of Olney & Winter 1985 (the source of HJ15's law) and of
//              Winter's EMG-to-force processing (about 3 Hz, tau ~ 50 ms); LB03 eq. 1 is its
//              discrete recursive form.
//
// Outside the calibrated range the nonlinear terms continue without exploding (emg-predict on a
// trial unlike the calibration): a(u) continues along its tangent below u = 0 and above u = 1 (C1,
// linear in u like the linear form); with a calibration range (spec.bounded), the moment arm's
// angle q in alpha_q q is held at the nearest end of the calibrated angle range (the moment arm
// at its last calibrated value), and M_P continues along its tangent at that end.
//
// HJ15 eq. 26: tau = sum alpha_i e_i + beta q + gamma qd + offset, the form the linear model keeps
// (beta, gamma additive, as the README of shared/data/real_human measures it); the extensions:
//  - d_m: electromechanical delay (s), one common to every channel (spec.common_delay) or, after
//    it, of the twin muscle m the channel stands for (spec.delay_s overrides the common one);
//  - A: activation nonlinearity, LB03 eq. 2 (Lloyd & Besier 2003) (A-shape factor, -3 < A < 0);
//  - alpha_q,i: moment arm changing with the joint angle, alpha_i (1 + c_i q) = alpha_i + alpha_q,i q;
//  - M_P,j: the passive moment of Riener & Edrich 1999 (model/passive_torque.h) along the
//    coordinate, with a fitted scale s_P (1 = as published);
//  - a missing gluteus maximus (no GMAX channel): the vasti channels at the hip, GMAX's synergists of
//    the weight-acceptance module (Neptune, Kautz & Zajac 2004; Ivanenko et al. 2004);
//  - collinear channels of one muscle (the vasti, the two hamstrings) pooled (spec.pooled): one alpha
//    of their mean envelope, channel named "a+b";
//  - robust fit: rows whose moment lies beyond kSpikeMads scaled MADs of the median left out of the
//    fit (the contact spikes of inverse dynamics).
// Channels act at the joints their muscle spans (sim/muscles.h ActionSign); alpha is fitted free of
// sign (its expected sign is reported) or, with spec.signed_alphas, constrained to it. Least squares on rows weighted by 1/SD of each joint's
// moment, both joints in one stack (diagnosis/diagnose_select.h FitCols), standard errors corrected
// for the residual's autocorrelation.
#pragma once
#include <array>
#include <map>
#include <string>
#include <vector>

#include "emg/emg_msk_model.h"
#include "emg/emg_recording.h"

namespace exotwin {

// Samples beyond this many scaled MADs (1.4826 MAD) of the median moment are contact spikes: left
// out of every held-out score (issue 19) and, with spec.robust, of the fit.
constexpr double kSpikeMads = 6.0;

// The structure of the model: which extensions are on.
struct EmgModelSpec {
  double common_delay = 0;                 // electromechanical delay of every channel, s
  double twitch = 0;                       // twitch time constant tau of every channel, s (0: none)
  std::map<Muscle, double> delay_s;        // per twin muscle, s (absent: common_delay)
  std::vector<Muscle> pooled;              // muscles whose channels enter as one mean envelope
  double a_shape = 0;                      // Lloyd & Besier A; 0 = linear activation
  bool moment_arm[2] = {false, false};     // alpha_q terms at the hip / knee
  bool passive[2] = {false, false};        // Riener & Edrich passive moment at the hip / knee
  bool gmax_proxy = false;                 // vasti channels at the hip when GMAX is missing
  bool robust = false;                     // spikes left out of the fit rows
  // Every alpha keeps the sign of its muscle's action at the joint (EmgTerm::ExpectedSign): a
  // muscle only pulls, so its moment has the sign of its moment arm (HJ15 eq. 23-24 signs).
  // Sign-constrained least squares (diagnose_select.h SolveSigned); an alpha the data would give
  // the other sign is held at zero (EmgTerm::held), the channel not separable at that joint.
  bool signed_alphas = false;
  // Standard errors of the searched parameters (profile of the fit's sum of squares), 0 if unknown.
  double common_delay_se = 0, twitch_se = 0;  // s
  std::map<Muscle, double> delay_se;       // s
  double a_shape_se = 0;
  // Calibrated angle range per joint (rad): angle-dependent terms continue as the header says
  // outside it. Off while fitting (the data's range is the range).
  bool bounded = false;
  double q_lo[2] = {0, 0}, q_hi[2] = {0, 0};
  double Delay(Muscle m) const;
  bool Pooled(Muscle m) const;
};

// The range each input of a calibration covered (emg-predict's extrapolation report).
struct EmgCalibrationRange {
  std::vector<std::string> channels;       // as recorded (not pooled)
  std::vector<double> e_lo, e_hi;          // envelope per channel
  double q_lo[2] = {0, 0}, q_hi[2] = {0, 0};    // rad
  double qd_lo[2] = {0, 0}, qd_hi[2] = {0, 0};  // rad/s
  bool empty() const { return channels.empty(); }
};

// The range of `recs` (same channels).
EmgCalibrationRange RangeOf(const std::vector<const EmgRecording*>& recs);

// Share of the samples of `rec` outside `range`, per channel (envelope) and per joint (angle,
// velocity). A channel the range lacks counts as wholly outside.
struct EmgExtrapolation {
  std::vector<std::string> channels;
  std::vector<double> envelope_share;
  double angle_share[2] = {0, 0}, velocity_share[2] = {0, 0};
};
EmgExtrapolation ExtrapolationOf(const EmgCalibrationRange& range, const EmgRecording& rec);

// Most of a recording's samples outside the calibration's range at a joint: another gait than the one
// calibrated (issue 42: a model calibrated on walking, applied to running). There every cause the
// calibration added to the papers' form was validated on none of the samples, and its structure is
// not what carries: emg-predict predicts the joint by the papers' form (EmgTorqueModel::papers_terms).
constexpr double kOtherGaitShare = 0.5;

// Share of the samples of `rec` where an input of joint j leaves `range`: either joint's angle or
// velocity (the forms read both: passive moments and biarticular paths), or the envelope of a channel
// whose muscle spans j (the vasti at the hip too where `gmax_proxy`); a channel the range lacks is no
// input of the calibrated model and is not counted (ExtrapolationOf reports it).
double JointOutsideShare(const EmgCalibrationRange& range, const EmgRecording& rec, int joint, bool gmax_proxy);

enum class TermKind { kAlpha, kAlphaQ, kBeta, kGamma, kOffset, kPassive };

// One fitted parameter.
struct EmgTerm {
  int joint = 0;  // 0 hip, 1 knee
  TermKind kind = TermKind::kOffset;
  std::string channel;            // alpha / alpha_q
  Muscle muscle = Muscle::kGMAX;  // the twin muscle of the channel
  bool proxy = false;             // a vasti channel standing in for the missing GMAX at the hip
  double value = 0, se = 0;
  bool held = false;              // alpha held at zero by spec.signed_alphas (se 0)
  // Sign of the muscle's action at the joint (sim/muscles.h ActionSign; a proxy: GMAX's), for
  // alpha and alpha_q; 0 for the other terms.
  int ExpectedSign() const;
  std::string Name() const;       // e.g. "alpha[rect_fem_r]", "alpha_q[vas_lat_r as GMAX]", "beta"
  std::string Unit() const;       // e.g. "N m", "N m/rad", "N m s/rad", "1"
  std::string Kind() const;       // "alpha", "alpha_q", "beta", "gamma", "offset", "passive_scale"
};

struct EmgJointFigures {
  double r2_fit = 0;         // fit rows
  double r2_heldout = 0;     // all held-out samples
  double rms_heldout = 0;    // N m
  double r2_heldout_trim = 0, rms_heldout_trim = 0;  // held-out samples within kSpikeMads of the median
  double r2_cv = 0, rms_cv = 0;      // cross-validation (folds left out in turn), within kSpikeMads
  size_t heldout = 0, trimmed = 0;                    // held-out samples, and those left out as spikes
};

struct EmgTorqueModel {
  EmgModelSpec spec;
  std::vector<EmgTerm> terms;
  std::vector<std::string> missing;  // twin muscles without a channel
  double autocorr_rows = 1;          // residual autocorrelation length the standard errors use
  EmgJointFigures figures[2];        // of the fit that produced the coefficients
  double bic = 0;                    // of that fit (columns + nonlinear parameters)
  double weight[2] = {0, 0};         // row weights of the fit, 1/N m
  double sse_fit = 0, n_fit = 0;     // weighted SSE and row count of the fit rows
  double sse_heldout[2] = {0, 0};    // weighted held-out SSE per joint (time split), for the loop
  // Cross-validation (weighted SSE per joint over samples within kSpikeMads): each fold left out in
  // turn and predicted by the fit on the other folds' rows. Folds: the recordings (>= 2), or
  // contiguous blocks of the one recording.
  std::vector<std::array<double, 2>> sse_fold;
  double sse_cv[2] = {0, 0};
  bool folds_are_recordings = false;
  EmgCalibrationRange range;         // of the recordings fitted
  int nonlinear_parameters() const;  // delays and A
  // The musculoskeletal form (emg_msk_model.h) beside this linear one, and per joint which of the two
  // predicts (issue 42: chosen by the same blocked cross-validation; the linear form otherwise).
  EmgMskModel msk;
  bool msk_form[2] = {false, false};
  // The papers' form (HJ15 eq. 26: alphas free of sign, beta, gamma, offset; no delay, twitch or other
  // cause) fitted on every sample of the calibration: what predicts a joint on another gait
  // (kOtherGaitShare). Empty in files written before it: no such fallback.
  std::vector<EmgTerm> papers_terms;
};

// The terms of `spec` for the channels of `rec` (coefficients zero).
std::vector<EmgTerm> TermsOf(const EmgModelSpec& spec, const EmgRecording& rec);

// Activation a(u) of LB03 eq. 2 (Lloyd & Besier 2003) with shape factor A (A = 0: u) on 0 <= u <= 1,
// continued along its tangent outside (header).
double ActivationShape(double u, double A);

// Riener & Edrich 1999's passive moment along coordinate j (N m; minus P of HJ15 eq. 1) at the angles
// (q0, q1) (rad, hip and knee); with a calibrated range (q_lo, q_hi: two angles each) continued along
// its tangent outside it, so that its exponentials do not explode beyond the angles it was fitted on.
double PassiveMomentAlong(int j, double q0, double q1, const double* q_lo = nullptr, const double* q_hi = nullptr);

// The twitch filter T_tau (header) of u sampled at times t (causal, starts at rest at u[0]).
std::vector<double> TwitchFilter(const std::vector<double>& t, const std::vector<double>& u, double tau);

// The envelope of `channel` in `rec` ("a+b": the mean of a and b). Throws InputError when missing.
std::vector<double> ChannelEnvelope(const EmgRecording& rec, const std::string& channel);

// The regressor of `term` on every sample of `rec` (N m per unit of the term's coefficient).
// Throws InputError when the recording lacks the term's channel.
std::vector<double> TermColumn(const EmgTerm& term, const EmgModelSpec& spec, const EmgRecording& rec);

// Estimated joint moment (N m) at joint j on every sample of `rec`: the linear form's, or at a joint in
// the musculoskeletal form its moment, except on the samples where a muscle spanning the joint leaves
// its calibrated fibre length or velocity: there the linear form, validated on the same calibration,
// stands in (PredictMoments says where). On another gait (more than kOtherGaitShare of the samples
// outside the calibration's range at the joint, JointOutsideShare) the papers' form predicts the whole
// recording at that joint, whatever its form (when the model has papers_terms).
std::vector<double> PredictMoment(const EmgTorqueModel& model, const EmgRecording& rec, int joint);

struct EmgPrediction {
  std::vector<double> tau[2];       // N m
  std::vector<char> fallback[2];    // samples predicted by the linear form in place of the musculoskeletal one
  double fallback_share[2] = {0, 0};
  double outside_share[2] = {0, 0};  // JointOutsideShare (0 without a calibration range)
  bool papers[2] = {false, false};   // another gait: the papers' form predicts the joint
  EmgMskSeries msk;                 // the musculoskeletal series (empty without msk.present)
};
EmgPrediction PredictMoments(const EmgTorqueModel& model, const EmgRecording& rec);
// The linear form's moment (HJ15 eq. 26 and the loop's terms), whatever the joint's form.
std::vector<double> PredictLinearMoment(const EmgTorqueModel& model, const EmgRecording& rec, int joint);

// Indices of the samples [a, b) of x within kSpikeMads scaled MADs of their median.
std::vector<size_t> WithinSpikeLimit(const std::vector<double>& x, size_t a, size_t b);

// R^2 = 1 - SS_res / SS_tot (about the measured mean) and RMS error over the samples `idx`.
void ScoreSamples(const std::vector<double>& measured, const std::vector<double>& predicted,
                  const std::vector<size_t>& idx, double* r2, double* rms);

struct EmgFitOptions {
  double train_fraction = 0.7;  // first part of every recording fitted, the rest held out; 1 = all
  double weight[2] = {0, 0};    // row weights per joint (1/N m); 0: 1/SD of the moment's fit rows
  double autocorr_rows = 0;     // 0: from this fit's residual
  int blocks = 5;               // one recording: contiguous cross-validation blocks (>= 2)
  bool fit_only = false;        // coefficients, BIC and sse_fit only (no scores, figures, range)
};

// Least-squares fit of `spec` on recordings with moments (>= 1). Fills coefficients, standard
// errors, the figures (pooled over recordings) and the loop's scores.
EmgTorqueModel FitEmgModel(const EmgModelSpec& spec, const std::vector<const EmgRecording*>& recs,
                           const EmgFitOptions& opt = {});

// EMGMODEL.yaml: every parameter with its unit and standard error (DESIGN.md "EMG model file").
std::string EmgModelYaml(const EmgTorqueModel& model, const std::vector<std::string>& header_comments);
// Reads EMGMODEL.yaml; throws InputError naming the file and key.
EmgTorqueModel ReadEmgModel(const std::string& path);

}  // namespace exotwin
