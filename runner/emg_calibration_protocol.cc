// EMG calibration protocol of Hwang & Jeon 2015 sec. 4.3 on the EXOwheel twin: see the header.
#include "runner/emg_calibration_protocol.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "formats/csv_table.h"
#include "emg/emg_calibration.h"
#include "formats/measured_data.h"
#include "dsp/statistics.h"
#include "controller/muscular_torque.h"
#include "core/output_path.h"
#include "core/error.h"
#include "dsp/emg_envelope.h"
#include "dsp/mvc.h"
#include "hwsim/emg_amplifier.h"
#include "model/leg_dynamics.h"
#include "runner/remote_controller.h"
#include "sim/anthropometry.h"
#include "sim/synthetic_emg.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

constexpr double kDt = 1e-3;            // s: EMG and log sample period (1 kHz)
constexpr double kHoldRamp = 0.2;       // s: controller fade-in of the isometric holds
constexpr double kGaitRamp = 2.0;       // s: controller fade-in of the gait (as gait_2kmh.yaml)
constexpr double kStride = 2.0;         // s: 2 km/h stride (paper sec. 3.4)
constexpr double kTail = 1.0;           // s recorded after the evaluated window (filter edges)
// Peak muscular torque the isometric contractions aim at, N m: 2/3 of the +-120 N m range of the
// EXOwheel torque sensors (hwsim::TorqueSensorSpec::range), leaving room for the held leg's gravity
// and the hold's transients below the supervisor's sensor limit. The subject follows targets shown on
// the torque display (sec. 4.3 gives "different levels" only): a strong subject's 30 % MVC knee
// extension (> 100 N m) would otherwise saturate the sensor and trip the safe state.
constexpr double kIsometricTorqueBudget = 80.0;
const char* const kJoint[2] = {"hip", "knee"};
const char* const kModel[3] = {"identified", "deleva", "dempster"};

// Linear envelopes (HJ15 eq. 23 chain, V) of the emg_* columns of a record sampled at 1 kHz.
std::vector<std::vector<double>> Envelopes(const CsvTable& t, const std::string& source) {
  std::vector<std::vector<double>> env;
  for (int c = 0; c < kNumMuscles; ++c) {
    const std::string name = std::string("emg_") + MuscleName(MuscleAt(c));
    const int i = t.Find(name);
    if (i < 0) throw InputError(source + ": no column " + name + " (the EMG amplifier was not recorded)");
    env.push_back(dsp::LinearEnvelopeZeroPhase(t.columns[i], 1.0 / kDt));
  }
  return env;
}

// Row range [a, b) of a time column inside [t0, t1) s.
std::pair<size_t, size_t> Window(const std::vector<double>& t, double t0, double t1) {
  const size_t a = std::lower_bound(t.begin(), t.end(), t0) - t.begin();
  const size_t b = std::lower_bound(t.begin(), t.end(), t1) - t.begin();
  return {a, std::max(a, b)};
}

// MVC trials of muscle m against manual resistance, leg held at `pose` by the examiner (no torque
// sensor involved); electrode voltages through the rig's amplifier (hwsim). Writes `path` and
// returns the MVC value (V): mean of the trial peaks of the recorded channel's linear envelope.
double RecordMvc(const MuscleParams& mp, Muscle m, int trials, const Eigen::Vector2d& pose, uint64_t seed,
                 const std::string& path, const std::string& comment) {
  ContractionProgramme prog = MvcProgramme(m, trials);
  MuscleModel muscles(mp, kDt);
  SyntheticEmg emg(ExowheelSyntheticEmgConfig(), seed);
  hwsim::EmgAmplifier amplifier;
  std::vector<std::string> names = {"t"};
  for (int c = 0; c < kNumMuscles; ++c) names.push_back(std::string("emg_") + MuscleName(MuscleAt(c)));
  {
    CsvStreamWriter w(path, names, {comment});
    const long n = std::lround((prog.duration() + 1.0) / kDt);
    for (long k = 0; k < n; ++k) {
      muscles.Step(prog.Excitation(k * kDt, pose, Eigen::Vector2d::Zero()));
      const MuscleVec v = emg.Sample(muscles.electrical_activation());
      std::array<double, kNumMuscles> in{};
      for (int c = 0; c < kNumMuscles; ++c) in[c] = v[c];
      const auto out = amplifier.Sample(in);
      double row[1 + kNumMuscles] = {(k + 1) * kDt};
      for (int c = 0; c < kNumMuscles; ++c) row[1 + c] = out[c];
      w.Row(row, 1 + kNumMuscles);
    }
  }
  // From the recorded file, as an analyst would.
  const CsvTable t = ReadCsv(path);
  const std::vector<std::vector<double>> env = Envelopes(t, path);
  const std::vector<double>& time = t.columns[t.Find("t")];
  std::vector<std::pair<size_t, size_t>> w;
  for (const ContractionBlock& b : prog.blocks()) w.push_back(Window(time, b.t_start, b.t_start + 2 * b.ramp + b.hold));
  return dsp::MvcOfTrials(env[static_cast<int>(m)], w);
}

// A stop request (SIGINT / SIGTERM) ended a sub-trial: the protocol stops there (its fits need whole
// trials); RunEmgCalibrationScenario writes result.json with the sub-trial's interruption.
struct ProtocolInterrupted {
  RunInterruption stop;
};

// Runs a sub-trial through the EXOwheel runner into DIR/<tag>; returns its result (checks dropped).
// Throws ProtocolInterrupted if a stop request ended it.
RunResult RunTrial(Scenario sub, const std::string& tag, uint64_t seed, const RunOptions& opt) {
  sub.name += "/" + tag;
  sub.emg_calibration.reset();
  sub.checks.clear();
  sub.protocol.trials = 1;
  sub.log_measured_csv = true;
  sub.log_rate_hz = 1.0 / kDt;
  RunOptions ro;
  ro.out_dir = opt.out_dir + "/" + tag;
  ro.seed = seed;
  ro.progress = opt.progress;
  ro.remote = opt.remote;  // the same controller process runs every sub-trial (its configuration per trial)
  fs::remove_all(ro.out_dir);
  RunResult r = RunScenario(sub, ro);
  if (r.interrupted) throw ProtocolInterrupted{*r.interrupted};
  return r;
}

struct IsometricResult {
  AlphaFit fit;
  FitQuality dir[2];  // flexion, extension (Table 6)
};

// The runner trials' totals over the stages: worst safe state, logged samples, peak torques.
struct TrialTotals {
  double safe = 0, torque_max[2] = {0, 0}, samples = 0;
  // Adds trial r (written under DIR/<tag>) to the totals and its files and events to `result`.
  void Absorb(const RunResult& r, const std::string& tag, RunResult& result) {
    safe = std::max(safe, r.metrics.at("safe_state_entered"));
    samples += r.metrics.at("samples");
    for (int j = 0; j < 2; ++j)
      torque_max[j] = std::max(torque_max[j], r.metrics.at(std::string("torque_max_") + kJoint[j]));
    for (const std::string& f : r.files) result.files.push_back(tag + "/" + f);
    for (const std::string& e : r.events) result.events.push_back(tag + ": " + e);
  }
};

// LE = envelope / MVC at sample k, as the paper (no resting-level subtraction; see the Table 7 error
// budget in tests/emg/emg_calibration_test.cc).
MuscleVec Normalized(const std::vector<std::vector<double>>& env, size_t k, const MuscleVec& mvc) {
  return NormalizedEnvelope(env, k, MuscleVec::Zero(), mvc);
}

// Stage 1: MVC trials of every muscle (GMAX, RF, ST at the hip pose, standing; VM, GAS at the knee
// pose, seated) into DIR/mvc/; returns the MVC per muscle (V), adds files and mvc_* metrics to result.
MuscleVec MvcStage(const Scenario& s, const MuscleParams& mp, const RunOptions& opt, RunResult& result) {
  const EmgCalibrationSpec& cal = *s.emg_calibration;
  CreateOutputFolder(opt.out_dir + "/mvc");
  MuscleVec mvc;
  for (int c = 0; c < kNumMuscles; ++c) {
    const Muscle mu = MuscleAt(c);
    const bool knee = mu == Muscle::kVM || mu == Muscle::kGAS;
    const double* pose = knee ? cal.knee_pose : cal.hip_pose;
    const std::string file = std::string("mvc/mvc_") + MuscleName(mu) + ".csv";
    mvc[c] = RecordMvc(mp, mu, cal.mvc_trials, {pose[0], pose[1]}, MixSeed(result.seed ^ (0x6d7663ull + c)),
                       opt.out_dir + "/" + file,
                       "exotwin run " + s.name + ": MVC trials of " + MuscleName(mu) + ", seed " +
                           std::to_string(result.seed));
    if (!(mvc[c] > 0)) throw InputError(s.source + ": MVC of " + MuscleName(mu) + " is zero (no EMG recorded)");
    result.files.push_back(file);
    result.metrics[std::string("mvc_") + MuscleName(mu) + "_V"] = mvc[c];
  }
  return mvc;
}

// Stage 2, joint j: isometric trial with the exoskeleton holding the pose, HJ15 eq. 23-25 alpha
// against tau_S minus its relaxed reading, Table 6 R^2 / NRMS per direction; iso_* and alpha_* metrics.
IsometricResult IsometricStage(const Scenario& s, int j, const MuscleParams& mp, const MuscleVec& mvc,
                               const RunOptions& opt, RunResult& result, TrialTotals& totals) {
  const EmgCalibrationSpec& cal = *s.emg_calibration;
  auto& m = result.metrics;
  IsometricResult iso;
  Scenario sub = s;
  const double* pose = j == 0 ? cal.hip_pose : cal.knee_pose;
  sub.fixed_joints = {{"hip", pose[0]}, {"knee", pose[1]}};
  sub.protocol.trajectory = TrajectoryKind::kHold;
  sub.protocol.ramp = kHoldRamp;
  sub.human.behaviour = j == 0 ? "isometric_hip" : "isometric_knee";
  sub.human.programme_seed = MixSeed(result.seed ^ (0x69736full + j));
  // Levels scaled down (all blocks alike) so that no contraction asks for more than the torque
  // budget at either joint (HJ15 eq. 23-24 at the programme's peaks; biarticular RF / ST load both).
  double peak_torque = 0;
  const ContractionProgramme planned = IsometricProgrammeOf(sub.human, 0);
  for (const ContractionBlock& blk : planned.blocks())
    for (int jj = 0; jj < 2; ++jj)
      peak_torque = std::max(peak_torque, std::abs(IsometricTorque(jj, mp.alpha.col(jj), blk.peak)));
  const double scale = std::min(1.0, kIsometricTorqueBudget / peak_torque);
  sub.human.levels[0] *= scale;
  sub.human.levels[1] *= scale;
  m[std::string("iso_level_scale_") + kJoint[j]] = scale;
  const ContractionProgramme prog = IsometricProgrammeOf(sub.human, 0);
  sub.protocol.duration = prog.duration() + kTail;
  const std::string tag = std::string("isometric_") + kJoint[j];
  const RunResult r = RunTrial(sub, tag, MixSeed(result.seed ^ (0x69736f00ull + j)), opt);
  totals.Absorb(r, tag, result);
  const std::string path = opt.out_dir + "/" + tag + "/measured.csv";
  const MeasuredData d = ReadMeasuredCsv(path);
  const std::vector<std::vector<double>> env = Envelopes(d.table, path);
  const std::vector<double>& tau_S = j == 0 ? d.tau_hip() : d.tau_knee();
  // The sensor reads gravity of the held leg plus the muscles: its relaxed reading before the
  // first contraction is subtracted, so tau^ISO is the muscular torque alone (sec. 4.3).
  const auto base = Window(d.t(), kHoldRamp + 0.1, prog.blocks().front().t_start);
  if (base.second - base.first < 100) throw InputError(s.source + ": isometric trial: no relaxed lead-in");
  const double offset = RestLevel(tau_S, base.first, base.second);  // mean relaxed reading
  const auto all = Window(d.t(), kHoldRamp + 0.1, prog.duration() + 0.5);
  std::vector<MuscleVec> le;
  std::vector<double> tau;
  for (size_t k = all.first; k < all.second; ++k) {
    le.push_back(Normalized(env, k, mvc));
    tau.push_back(tau_S[k] - offset);
  }
  iso.fit = FitIsometricAlpha(j, le, tau);  // HJ15 eq. 25
  // Table 6 per direction: the contractions of that direction (even blocks act along +q).
  for (int dir = 0; dir < 2; ++dir) {
    std::vector<double> y, yhat;
    for (size_t b = 0; b < prog.blocks().size(); ++b) {
      const ContractionBlock& blk = prog.blocks()[b];
      const bool plus_q = b % 2 == 0;
      const bool flexion = j == 0 ? plus_q : !plus_q;  // hip flexion +q, knee flexion -q
      if (flexion != (dir == 0)) continue;
      const auto w = Window(d.t(), blk.t_start, blk.t_start + 2 * blk.ramp + blk.hold);
      for (size_t k = w.first; k < w.second; ++k) {
        y.push_back(tau_S[k] - offset);
        yhat.push_back(IsometricTorque(j, iso.fit.alpha, Normalized(env, k, mvc)));
      }
    }
    if (y.empty()) throw InputError(s.source + ": human.contractions: expected at least 2 (one per direction)");
    iso.dir[dir] = Quality(y, yhat);
    const std::string key = std::string(kJoint[j]) + (dir == 0 ? "_flexion" : "_extension");
    m["iso_r2_" + key] = iso.dir[dir].r2;
    m["iso_nrms_" + key + "_pct"] = iso.dir[dir].nrms_pct;
  }
  m[std::string("iso_r2_") + kJoint[j]] = iso.fit.quality.r2;
  m[std::string("iso_nrms_") + kJoint[j] + "_pct"] = iso.fit.quality.nrms_pct;
  for (int c = 0; c < kNumMuscles; ++c)
    if (ActionSign(MuscleAt(c), j) != 0)
      m[std::string("alpha_") + MuscleName(MuscleAt(c)) + "_" + kJoint[j]] = iso.fit.alpha[c];
  return iso;
}

// Table 6 summary over both joints and directions: iso_r2_mean, iso_nrms_mean_pct, iso_r2_min,
// iso_nrms_max_pct.
void IsometricSummary(const IsometricResult iso[2], RunResult& result) {
  double r2_sum = 0, nrms_sum = 0, r2_min = 1, nrms_max = 0;
  for (int j = 0; j < 2; ++j)
    for (int dir = 0; dir < 2; ++dir) {
      r2_sum += iso[j].dir[dir].r2;
      nrms_sum += iso[j].dir[dir].nrms_pct;
      r2_min = std::min(r2_min, iso[j].dir[dir].r2);
      nrms_max = std::max(nrms_max, iso[j].dir[dir].nrms_pct);
    }
  auto& m = result.metrics;
  m["iso_r2_mean"] = r2_sum / 4;
  m["iso_nrms_mean_pct"] = nrms_sum / 4;
  m["iso_r2_min"] = r2_min;
  m["iso_nrms_max_pct"] = nrms_max;
}

// Samples of the fitted window of the gait trial: LE per sample, q (rad), qd (rad/s) per joint, and
// tau_M of HJ15 eq. 9 (N m) per parameter set (kModel order) and joint.
struct GaitSamples {
  std::vector<MuscleVec> le;
  std::vector<double> q[2], qd[2], tau_M[3][2];
};

// Stage 3: the exaggerated gait at 2 km/h through the runner into DIR/gait/; returns the fitted
// window's samples, tau_M = HJ15 eq. 9 with the identified, De Leva and Dempster parameter sets.
GaitSamples DynamicTrialStage(const Scenario& s, const Subject& subject, const MuscleVec& mvc,
                              const RunOptions& opt, RunResult& result, TrialTotals& totals) {
  const EmgCalibrationSpec& cal = *s.emg_calibration;
  auto& m = result.metrics;
  Scenario sub = s;
  sub.protocol.trajectory = TrajectoryKind::kGait;
  sub.protocol.stride_period = kStride;
  sub.protocol.ramp = kGaitRamp;
  sub.human.behaviour = "exaggerated_gait";
  const double t_end = s.human.active_from + cal.strides * kStride;
  sub.protocol.duration = t_end + kTail;
  const RunResult r = RunTrial(sub, "gait", MixSeed(result.seed ^ 0x67616974ull), opt);
  totals.Absorb(r, "gait", result);
  m["gait_tracking_rms_hip_deg"] = r.metrics.at("tracking_rms_hip_deg");
  m["gait_tracking_rms_knee_deg"] = r.metrics.at("tracking_rms_knee_deg");
  const std::string path = opt.out_dir + "/gait/measured.csv";
  const MeasuredData d = ReadMeasuredCsv(path);
  const Kinematics kin = DeriveKinematics(d);  // zero-phase 20 Hz Butterworth, as sec. 3.2
  const std::vector<std::vector<double>> env = Envelopes(d.table, path);
  LegParams model[3];
  model[0] = ResolveSubject(s);  // the subject's identified parameters (Table 4; twin truth)
  model[0].passive = PassiveModel::kRiener1999;
  model[1] = model[2] = model[0];
  model[1].human = Table4AnthropometricLumped(AnthropometricModel::kDeLeva, subject.weight, model[0].L1, subject.L2);
  model[2].human = Table4AnthropometricLumped(AnthropometricModel::kDempster, subject.weight, model[0].L1, subject.L2);
  // Fitted window: the exaggerated strides, or the whole trial after the gait fade-in (fit_window).
  const double t_fit = cal.fit_window == "trial" ? std::min(kGaitRamp, s.human.active_from) : s.human.active_from;
  const auto w = Window(d.t(), t_fit, t_end);
  m["dyn_fit_window_s"] = t_end - t_fit;
  GaitSamples g;
  for (size_t k = w.first; k < w.second; ++k) {
    g.le.push_back(Normalized(env, k, mvc));
    const Eigen::Vector2d qk(kin.q[0][k], kin.q[1][k]), qdk(kin.qd[0][k], kin.qd[1][k]),
        qddk(kin.qdd[0][k], kin.qdd[1][k]);
    for (int j = 0; j < 2; ++j) {
      g.q[j].push_back(qk[j]);
      g.qd[j].push_back(qdk[j]);
    }
    for (int mi = 0; mi < 3; ++mi) {
      // HJ15 eq. 9-10: tau_M = tau_S - tau_PAS, tau_PAS = -(the actuator torque the relaxed leg needs).
      const Eigen::Vector2d tm =
          controller::MuscularTorque(model[mi], qk, qdk, qddk, Eigen::Vector2d(d.tau_hip()[k], d.tau_knee()[k]));
      for (int j = 0; j < 2; ++j) g.tau_M[mi][j].push_back(tm[j]);
    }
  }
  return g;
}

// Stage 4: HJ15 eq. 28 beta, gamma per parameter set and joint on the gait samples (Table 7), into
// fit[model][joint]; dyn_*, r2_margin_*, tau_M_* metrics.
void DynamicFitStage(const GaitSamples& g, const IsometricResult iso[2], const MuscleParams& mp,
                     BetaGammaFit fit[3][2], RunResult& result) {
  auto& m = result.metrics;
  const std::vector<MuscleVec>& le = g.le;
  for (int j = 0; j < 2; ++j) {
    std::vector<double> yhat_identified;  // HJ15 eq. 27 with the identified set's beta, gamma
    for (int mi = 0; mi < 3; ++mi) {
      fit[mi][j] = FitDynamicBetaGamma(j, iso[j].fit.alpha, mp.theta_c[j], le, g.q[j], g.qd[j], g.tau_M[mi][j]);
      const std::string key = std::string(kModel[mi]) + "_" + kJoint[j];
      m["dyn_r2_" + key] = fit[mi][j].quality.r2;
      m["dyn_nrms_" + key + "_pct"] = fit[mi][j].quality.nrms_pct;
      m["dyn_beta_" + key + "_e3_per_deg"] = 1e3 * fit[mi][j].beta_per_deg();
      m["dyn_gamma_" + key + "_e3_per_deg_s"] = 1e3 * fit[mi][j].gamma_per_deg_s();
      if (mi == 0) {
        for (size_t k = 0; k < le.size(); ++k)
          yhat_identified.push_back(DynamicTorque(j, iso[j].fit.alpha, fit[0][j].beta, fit[0][j].gamma,
                                                  mp.theta_c[j], le[k], g.q[j][k], g.qd[j][k]));
        continue;
      }
      m["r2_margin_" + key] = fit[0][j].quality.r2 - fit[mi][j].quality.r2;
      // How far the anthropometric model moves tau_M from the identified one, how much of that
      // shift is a copy of the effort itself (correlation with tau_M), and the R^2 the set would
      // get without refitting beta, gamma (the identified set's): the refit's share of the margin.
      double e2 = 0;
      std::vector<double> shift;
      for (size_t k = 0; k < g.tau_M[0][j].size(); ++k) {
        shift.push_back(g.tau_M[mi][j][k] - g.tau_M[0][j][k]);
        e2 += shift.back() * shift.back();
      }
      m["tau_M_shift_rms_" + key] = std::sqrt(e2 / g.tau_M[0][j].size());
      m["tau_M_shift_effort_corr_" + key] = Pearson(shift, g.tau_M[0][j]);
      m["r2_margin_fixed_beta_gamma_" + key] = fit[0][j].quality.r2 - Quality(g.tau_M[mi][j], yhat_identified).r2;
    }
    double s2 = 0;
    for (double v : g.tau_M[0][j]) s2 += v * v;
    m[std::string("tau_M_rms_identified_") + kJoint[j]] = std::sqrt(s2 / g.tau_M[0][j].size());
  }
}

// Stage 5: DIR/calibration.csv (one row per stage, joint and parameter set) and DIR/calibration.json
// (the same + MVC); dyn null when the dynamic stage did not run. Adds both files to result.
void ReportStage(const Scenario& s, const MuscleVec& mvc, const IsometricResult iso[2], const BetaGammaFit (*dyn)[2],
                 const RunOptions& opt, RunResult& result) {
  std::vector<std::string> names = {"stage", "joint", "model"};
  for (int c = 0; c < kNumMuscles; ++c) names.push_back(std::string("alpha_") + MuscleName(MuscleAt(c)));
  for (const char* n : {"beta", "gamma", "r2", "nrms_pct"}) names.push_back(n);
  std::string csv = "# exotwin run " + s.name + " seed " + std::to_string(result.seed) +
                    ": Hwang & Jeon 2015 eq. 25 (stage 0 isometric) and eq. 28 (stage 1 dynamic); alpha N m at MVC, "
                    "beta 1/rad, gamma s/rad; joint 0 hip, 1 knee; model 0 identified, 1 De Leva, 2 Dempster\n";
  for (size_t i = 0; i < names.size(); ++i) csv += (i ? "," : "") + names[i];
  csv += "\n";
  nlohmann::json js;
  js["scenario"] = s.name;
  js["seed"] = result.seed;
  for (int c = 0; c < kNumMuscles; ++c) js["mvc_V"][MuscleName(MuscleAt(c))] = mvc[c];
  auto row = [&](int stage, int j, int mi, const MuscleVec& a, double beta, double gamma, const FitQuality& q) {
    char buf[512];
    std::snprintf(buf, sizeof(buf), "%d,%d,%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", stage, j, mi, a[0],
                  a[1], a[2], a[3], a[4], beta, gamma, q.r2, q.nrms_pct);
    csv += buf;
  };
  for (int j = 0; j < 2; ++j) {
    row(0, j, 0, iso[j].fit.alpha, 0, 0, iso[j].fit.quality);
    nlohmann::json& ij = js["isometric"][kJoint[j]];
    for (int c = 0; c < kNumMuscles; ++c)
      if (ActionSign(MuscleAt(c), j) != 0) ij["alpha_Nm"][MuscleName(MuscleAt(c))] = iso[j].fit.alpha[c];
    ij["r2"] = iso[j].fit.quality.r2;
    ij["nrms_pct"] = iso[j].fit.quality.nrms_pct;
    for (int dir = 0; dir < 2; ++dir)
      ij[dir == 0 ? "flexion" : "extension"] = {{"r2", iso[j].dir[dir].r2}, {"nrms_pct", iso[j].dir[dir].nrms_pct}};
  }
  if (dyn)
    for (int mi = 0; mi < 3; ++mi)
      for (int j = 0; j < 2; ++j) {
        row(1, j, mi, iso[j].fit.alpha, dyn[mi][j].beta, dyn[mi][j].gamma, dyn[mi][j].quality);
        js["dynamic"][kModel[mi]][kJoint[j]] = {{"beta_per_rad", dyn[mi][j].beta},
                                                {"gamma_s_per_rad", dyn[mi][j].gamma},
                                                {"beta_e3_per_deg", 1e3 * dyn[mi][j].beta_per_deg()},
                                                {"gamma_e3_per_deg_s", 1e3 * dyn[mi][j].gamma_per_deg_s()},
                                                {"r2", dyn[mi][j].quality.r2},
                                                {"nrms_pct", dyn[mi][j].quality.nrms_pct}};
      }
  WriteFileAtomic(opt.out_dir + "/calibration.csv", csv);
  WriteFileAtomic(opt.out_dir + "/calibration.json", js.dump(2) + "\n");
  result.files.push_back("calibration.csv");
  result.files.push_back("calibration.json");
}

// The whole protocol for one subject (s.subject, s.human.muscle_seed) into opt.out_dir: files and
// metrics, no result.json. Stages 1-5 above, in order.
RunResult CalibrateOneSubject(const Scenario& s, const RunOptions& opt, uint64_t seed) {
  RunResult result;
  result.scenario = s.name;
  result.seed = seed;
  CreateOutputFolder(opt.out_dir);
  const std::optional<Subject> subject = ScenarioSubject(s);
  if (!subject) throw InputError(s.source + ": subject: emg_calibration needs preset or random_seed");
  const MuscleParams mp = DrawMuscleParams(s.human.muscle_seed);
  TrialTotals totals;

  const MuscleVec mvc = MvcStage(s, mp, opt, result);
  IsometricResult iso[2];
  for (int j = 0; j < 2; ++j) iso[j] = IsometricStage(s, j, mp, mvc, opt, result, totals);
  IsometricSummary(iso, result);
  BetaGammaFit dyn[3][2];
  const bool dynamic = s.emg_calibration->dynamic;
  if (dynamic) DynamicFitStage(DynamicTrialStage(s, *subject, mvc, opt, result, totals), iso, mp, dyn, result);

  auto& m = result.metrics;
  m["safe_state_entered"] = totals.safe;
  m["samples"] = totals.samples;  // logged by the runner trials (the MVC records are not counted)
  m["torque_max_hip"] = totals.torque_max[0];
  m["torque_max_knee"] = totals.torque_max[1];
  ReportStage(s, mvc, iso, dynamic ? dyn : nullptr, opt, result);
  return result;
}

// Aggregate of one metric over the subjects: the worst for limits (max of *_max*, safe_state_entered,
// min of *_min*), the mean otherwise (Tables 6-7 print means over 10 subjects).
double Aggregate(const std::string& key, const std::vector<double>& v) {
  if (key.find("max") != std::string::npos || key == "safe_state_entered") return *std::max_element(v.begin(), v.end());
  if (key.find("min") != std::string::npos) return *std::min_element(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

double StdDev(const std::vector<double>& v) {
  double mean = 0, ss = 0;
  for (double x : v) mean += x / static_cast<double>(v.size());
  for (double x : v) ss += (x - mean) * (x - mean);
  return v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
}

}  // namespace

RunResult RunEmgCalibrationScenario(const Scenario& s, const RunOptions& opt) {
  if (!s.emg_calibration) throw InputError(s.source + ": emg_calibration: missing");
  const auto wall0 = std::chrono::steady_clock::now();
  const uint64_t seed = opt.seed ? *opt.seed : s.seed;
  const int n = s.emg_calibration->subjects;
  RunResult result;
  result.scenario = s.name;
  result.seed = seed;
  try {
    if (n <= 1) {
      result = CalibrateOneSubject(s, opt, seed);
    } else {
      // The paper's population: Table 4's subjects S1..Sn (anthropometry and identified parameters),
      // each with its own ground-truth muscles (human.muscle_seed + i - 1) and trial seeds.
      result.scenario = s.name;
      result.seed = seed;
      std::map<std::string, std::vector<double>> per_key;
      for (int i = 1; i <= n; ++i) {
        Scenario si = s;
        si.subject = SubjectSpec{};
        si.subject.preset = "S" + std::to_string(i);
        si.subject.passive = s.subject.passive;
        si.human.muscle_seed = s.human.muscle_seed + static_cast<uint64_t>(i - 1);
        RunOptions oi = opt;
        const std::string dir = "subject_S" + std::to_string(i);
        oi.out_dir = opt.out_dir + "/" + dir;
        const RunResult ri = CalibrateOneSubject(si, oi, MixSeed(seed ^ (0x73756266ull + i)));
        for (const std::string& f : ri.files) result.files.push_back(dir + "/" + f);
        for (const auto& kv : ri.metrics) {
          per_key[kv.first].push_back(kv.second);
          result.metrics[dir + "." + kv.first] = kv.second;
        }
      }
      for (const auto& kv : per_key) {
        if (kv.second.size() != static_cast<size_t>(n)) continue;  // present for every subject only
        result.metrics[kv.first] = Aggregate(kv.first, kv.second);
        if (kv.first.rfind("iso_r2", 0) == 0 || kv.first.rfind("iso_nrms", 0) == 0 ||
            kv.first.rfind("dyn_r2", 0) == 0 || kv.first.rfind("r2_margin", 0) == 0) {
          result.metrics[kv.first + "_sd"] = StdDev(kv.second);
          if (kv.first.rfind("r2_margin", 0) == 0)
            result.metrics[kv.first + "_subjects_positive"] = static_cast<double>(
                std::count_if(kv.second.begin(), kv.second.end(), [](double x) { return x > 0; }));
        }
      }
      result.metrics["subjects"] = n;
    }
  } catch (const ProtocolInterrupted& e) {  // metrics: the subjects completed before the stop
    result.interrupted = e.stop;
  }
  if (opt.remote) opt.remote->AddMetrics(&result.metrics);
  result.metrics["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  FinishRun(s, result, opt.out_dir + "/result.json");
  return result;
}

}  // namespace exotwin
