// The musculoskeletal form of the EMG-driven joint moment (issue 42), beside the linear form of
// emg_torque_model.h, in CEINMS's family (Lloyd & Besier 2003; Pizzolato et al. 2015, CEINMS):
// each recorded channel drives one musculotendon unit (sim/musculotendon.h) whose force acts at
// every joint its path crosses through the moment arm of that path (a biarticular muscle: one force,
// two moments). Per joint j:
//
//   tau_j(t) = sum_c s_c F_max,c (a_c(t) f_L(l_c) f_V(v_c) + f_PE(l_c)) cos(phi_c) r_c,j(q)
//              + beta_j q_j + gamma_j qd_j + offset_j + passive_scale_j M_P,j(q)
//   a_c(t)   = the activation of emg_torque_model.h: A-shape (LB03 eq. 2) of the twitch-filtered
//              envelope delayed by the electromechanical delay (one common A and delay here)
//   l_c, v_c = fibre length and velocity of the unit along its path length L_c(q) (q: hip, knee and,
//              for the gastrocnemius, the recording's ankle angle): with Thelen's elastic tendon in
//              series (sim/musculotendon.h ElasticTendonSeries: the force above equals the tendon's,
//              F_max f_T(strain), the fibre's dynamics by backward Euler on the samples); with a rigid
//              tendon (models written before it) RigidTendonState at L_c and -sum_j r_c,j qd_j
//
// beta, gamma, offset carry what the recorded muscles do not (the muscles nobody recorded, passive
// tissues): the terms of the linear form's remainder (HJ15 eq. 26); passive_scale the passive tissues'
// moment in Riener & Edrich 1999's form, as the linear form's passive term (M_P along coordinate j,
// continued along its tangent outside the calibration's angles), free of sign like beta.
// Calibrated parameters and their bounds (CEINMS-RT's calibration,
// StrengthCoefficients_ShapeFactor_TendonSlackLength_single: strength 0.5-1.5 x F_max, A in (-3, 0),
// tendon slack length +-5 % and optimal fibre length +-2.5 % of the subject-scaled model):
// s_c within [0.5, 1.5] (bounded least squares, with beta, gamma, offset free, rows of both joints
// weighted by 1/SD of each joint's moment and the contact spikes left out); l_opt,c and l_ts,c within
// their bounds of the scaled gait2392 values (ScaledMusculotendon), searched channel by channel;
// A and the common delay (10-100 ms, Cavanagh & Komi 1979) searched on the nominal lengths first.
#pragma once
#include <array>
#include <map>
#include <string>
#include <vector>

#include "emg/emg_recording.h"
#include "sim/musculotendon.h"

namespace exotwin {

// Bounds of the calibration (header).
constexpr double kTendonSlackChange = 0.05;                 // +- fraction of the nominal l_ts
constexpr double kOptimalFibreChange = 0.025;               // +- fraction of the nominal l_opt

// A muscle of the twin's set that the recording lacks (EmgRecording::missing, the gluteus maximus of
// the development trial) is synthesized from the recorded excitations, as the synergy extrapolation of
// Ao, Shourijeh, Patten & Fregly 2020 (Front Comput Neurosci; the NMSM Pipeline's SynX) estimates an
// unmeasured excitation as a combination of the measured ones: its activation is sum_k w_k a_k of the
// recorded channels' activations, w_k >= 0 (an excitation does not go below zero), on its own gait2392
// path. Each term is one unit here (`synthesized`, `channel` the source, strength = w_k x its F_max,
// within [0, kStrengthHi]); with a rigid tendon and the active force only the units add up to exactly
// one muscle's active force, F_max cos(phi) f_L(l) f_V(v) sum_k w_k a_k, l and v of its path. Rigid:
// glut_max2's tendon is shorter than its fibre (l_ts / l_opt 0.86), where a rigid tendon is adequate
// (Millard, Uchida, Seth & Delp 2013, J Biomech Eng 135:021005). Active only: the passive stretch of unrecorded tissues is
// the remainder's passive moment (Riener & Edrich 1999, a whole joint's).
constexpr double kSynthesizedStrengthLo = 0.0;

struct EmgMskMuscle {
  std::string channel;
  Muscle muscle = Muscle::kVM;          // the path (sim/musculotendon.h)
  bool synthesized = false;             // an unrecorded muscle's term driven by `channel` (above)
  MusculotendonParams nominal;          // F_max of the channel's actuator, lengths of its path, scaled
  double strength = 1;                  // x F_max
  double strength_lo = kStrengthLo, strength_hi = kStrengthHi;  // its bounds (a map file may narrow them)
  double l_opt = 0, l_ts = 0;           // m
  // Calibrated range of the muscle's state (emg-predict's fallback): normalized fibre length and
  // velocity over the calibration samples.
  double fibre_lo = 0, fibre_hi = 0, velocity_lo = 0, velocity_hi = 0;
  MusculotendonParams Params() const;   // nominal with the calibrated lengths
  std::string Label() const;            // the channel, or "GMAX from <channel>" for a synthesized term
  std::string MuscleLabel() const;      // the channel, or "GMAX (synthesized)": the muscle a term belongs to
};

struct EmgMskModel {
  bool present = false;
  // Thelen's elastic tendon in series with the fibre (sim/musculotendon.h ElasticTendonSeries), or the
  // rigid one (a file written before the elastic tendon: `tendon:` absent).
  bool elastic_tendon = true;
  double delay = 0, twitch = 0, a_shape = 0;  // s, s, 1
  std::vector<EmgMskMuscle> muscles;
  double beta[2] = {0, 0}, gamma[2] = {0, 0}, offset[2] = {0, 0};
  // The passive tissues' moment: passive_scale M_P(q), M_P Riener & Edrich 1999 (the linear form's
  // passive term, emg_torque_model.h PassiveMomentAlong), continued along its tangent outside the
  // calibration's angle range q_lo .. q_hi (rad, hip and knee).
  double passive_scale[2] = {0, 0};
  double q_lo[2] = {-10, -10}, q_hi[2] = {10, 10};
  // Cross-validation (the folds of the linear form: strengths and remainder refitted per fold; lengths, A and
  // delay kept from the whole calibration, as the linear form's folds keep its delays)
  // and fit figures per joint, within kSpikeMads of the median moment.
  double r2_cv[2] = {0, 0}, rms_cv[2] = {0, 0}, r2_fit[2] = {0, 0};
  // Share of the calibration moment the recorded muscles can reach at all (item 2): sum over the
  // scored samples of min(|tau|, M) / sum |tau|, M the moment of every muscle pulling in tau's
  // direction at full activation and kStrengthHi F_max (the others silent).
  double reachable_share[2] = {0, 0};
  // The same at the recorded activations (the calibration's delay, twitch and shape): what the
  // recorded muscles can reach as they were activated, every strength at its upper bound.
  double reachable_share_recorded[2] = {0, 0};
  // The largest activation x strength of a synthesized muscle, sum_k s_k a_k over its terms, on the
  // calibration samples (x F_max; one muscle's is at most kStrengthHi: checked, warned about by emg-fit).
  double synthesized_peak = 0;
  double seconds = 0;  // run time of the calibration (cross-validation included)
};

// Time series of a calibrated model on a recording.
struct EmgMskSeries {
  std::vector<double> tau[2];                         // N m
  std::vector<std::vector<double>> force, fibre;      // per muscle: N, l/l_opt
  std::vector<std::vector<double>> velocity;          // per muscle: v/v_max
  // Samples where a muscle spanning joint j leaves its calibrated fibre length or velocity range.
  std::vector<char> outside[2];
};
// Throws InputError when the recording lacks a channel of the model.
EmgMskSeries MskSeries(const EmgMskModel& m, const EmgRecording& rec);

struct EmgMskFitOptions {
  int blocks = 5;          // one recording: contiguous cross-validation blocks
  bool cross_validate = true;
  bool elastic_tendon = true;  // EmgMskModel::elastic_tendon
  bool synthesize_missing = true;  // the recordings' missing muscles from the recorded excitations (above)
  std::map<std::string, std::array<double, 2>> strength_bounds;  // per channel (MuscleMap::strength_bounds)
};

// Calibrates the form on recordings with moments (same channels). Channels whose gait2392 actuator
// is unknown take their twin muscle's path actuator (sim/musculotendon.h GenericMusculotendon).
EmgMskModel FitEmgMsk(const std::vector<const EmgRecording*>& recs, double twitch, const EmgMskFitOptions& opt = {});

}  // namespace exotwin
