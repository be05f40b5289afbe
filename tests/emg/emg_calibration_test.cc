// End-to-end EMG calibration on the twin (issue 6 item 5): ground-truth muscles (sim/muscles.h) ->
// synthetic EMG (sim/synthetic_emg.h) -> amplifier (gain 1000; the band-pass is in the envelope
// chain) -> linear envelope / MVC -> HJ15 eq. 25 alpha and HJ15 eq. 28 beta, gamma. Compared with the
// ground truth and with Tables 6-7 (isometric R^2 0.951-0.976, NRMS 5.03-8.12 %; dynamic R^2 0.935
// hip / 0.924 knee with identified parameters, 0.884 / 0.877 with De Leva, 0.879 / 0.872 Dempster).
// In-process (no plant: the exoskeleton imposes a sinusoidal gait, the sensor is truth + noise); the
// De Leva / Dempster rows use sim/anthropometry. Table7ErrorBudget switches off one error source at a
// time and prints the R^2 of the three parameter sets (the same pipeline runs on the full twin in
// scenarios/exowheel_emg_dynamic.yaml).
#include "emg/emg_calibration.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "core/rng.h"
#include "core/units.h"
#include "dsp/emg_envelope.h"
#include "dsp/mvc.h"
#include "model/leg_dynamics.h"
#include "sim/anthropometry.h"
#include "sim/subjects.h"
#include "sim/synthetic_emg.h"

namespace exotwin {
namespace {

constexpr double kDt = 1e-3;
constexpr double kPi = 3.14159265358979323846;
// The EXOwheel's recording set-up (Delsys Bagnoli, 3 uV relaxed baseline), as the shipped scenarios.
SyntheticEmgConfig g_cfg = ExowheelSyntheticEmgConfig();

struct Record {
  std::vector<MuscleVec> le;              // normalized envelopes
  std::vector<std::vector<double>> env;   // envelopes per channel (V, amplified)
  std::vector<Eigen::Vector2d> tau;       // muscular torque (N m)
  std::vector<Eigen::Vector2d> q, qd;
};

// Runs behaviour b for T s with kinematics kin(t) -> (q, qd) imposed (the exoskeleton holds or
// moves the joints); records the muscular torque and the processed EMG.
template <class Kin>
Record RunTrial(const MuscleParams& p, Behaviour& b, double T, Kin kin, uint64_t seed,
                double envelope_hz = 2.0, bool oracle = false) {
  MuscleModel muscles(p, kDt);
  SyntheticEmg emg(g_cfg, seed);
  Record r;
  std::vector<std::vector<double>> amp(kNumMuscles), e_true(kNumMuscles);
  const int n = static_cast<int>(T / kDt);
  for (int k = 0; k < n; ++k) {
    Eigen::Vector2d q, qd;
    kin(k * kDt, q, qd);
    muscles.Step(b.Excitation(k * kDt, q, qd));
    const MuscleVec x = emg.Sample(muscles.electrical_activation());
    for (int c = 0; c < kNumMuscles; ++c) amp[c].push_back(1000.0 * x[c]);  // amplifier gain 1000
    for (int c = 0; c < kNumMuscles; ++c) e_true[c].push_back(muscles.electrical_activation()[c]);
    r.tau.push_back(muscles.Torques(q, qd).total());
    r.q.push_back(q);
    r.qd.push_back(qd);
  }
  for (int c = 0; c < kNumMuscles; ++c) r.env.push_back(dsp::LinearEnvelopeZeroPhase(amp[c], 1000.0, envelope_hz));
  if (oracle)
    for (int c = 0; c < kNumMuscles; ++c) r.env[c] = e_true[c];
  return r;
}

void Normalize(Record& r, const MuscleVec& mvc, const MuscleVec& rest = MuscleVec::Zero()) {
  r.le.resize(r.tau.size());
  for (size_t k = 0; k < r.tau.size(); ++k) r.le[k] = NormalizedEnvelope(r.env, k, rest, mvc);
}

// MVC of every muscle from its own three MVC trials, as the paper.
MuscleVec MeasureMvc(const MuscleParams& p, uint64_t seed, MuscleVec* peak_over_plateau = nullptr,
                     double envelope_hz = 2.0, MuscleVec* rest = nullptr) {
  MuscleVec mvc;
  for (int m = 0; m < kNumMuscles; ++m) {
    ContractionProgramme prog = MvcProgramme(MuscleAt(m));
    const Record r = RunTrial(p, prog, prog.duration() + 1, [&](double, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
      q = p.theta_c;
      qd.setZero();
    }, seed + m, envelope_hz);
    std::vector<std::pair<size_t, size_t>> w;
    for (const auto& b : prog.blocks())
      w.push_back({static_cast<size_t>(b.t_start / kDt), static_cast<size_t>((b.t_start + 2 * b.ramp + b.hold) / kDt)});
    mvc[m] = dsp::MvcOfTrials(r.env[m], w);
    if (rest) (*rest)[m] = RestLevel(r.env[m], 200, 700);  // relaxed before the first trial (t0 = 1 s)
    double s = 0;
    size_t n = 0;
    for (const auto& b : prog.blocks())
      for (size_t k = static_cast<size_t>((b.t_start + b.ramp + 0.5) / kDt);
           k < static_cast<size_t>((b.t_start + b.ramp + b.hold) / kDt); ++k, ++n)
        s += r.env[m][k];
    if (peak_over_plateau) (*peak_over_plateau)[m] = mvc[m] / (s / n);
  }
  return mvc;
}

struct Calibrated {
  MuscleParams truth;
  MuscleVec mvc;
  MuscleVec peak_over_plateau;  // MVC by peaks / mean envelope on the MVC plateaus (>= 1)
  AlphaFit fit[2];
  FitQuality dir[2][2];  // [joint][0 flexion, 1 extension]
};

Calibrated CalibrateIsometric(uint64_t seed) {
  Calibrated c;
  c.truth = DrawMuscleParams(seed);
  c.mvc = MeasureMvc(c.truth, seed * 100, &c.peak_over_plateau);
  MuscleRng noise(MixSeed(seed ^ 0x5e));
  for (int j = 0; j < 2; ++j) {
    ContractionProgramme prog = IsometricProgramme(j, 8, 0.1, 0.5, 0.1, seed + j);  // paper: 5-8
    Record r = RunTrial(c.truth, prog, prog.duration() + 1, [&](double, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
      q = c.truth.theta_c;
      qd.setZero();
    }, seed * 100 + 10 + j);
    Normalize(r, c.mvc);
    std::vector<double> tau;
    for (const auto& t : r.tau) tau.push_back(t[j] + 0.3 * noise.Normal());  // torque sensor noise 0.3 N m
    c.fit[j] = FitIsometricAlpha(j, r.le, tau);
    // Table 6 reports flexion and extension separately: quality over each direction's contractions.
    for (int d = 0; d < 2; ++d) {
      std::vector<double> y, yhat;
      for (size_t b = 0; b < prog.blocks().size(); ++b) {
        const auto& blk = prog.blocks()[b];
        const int sign = (b % 2 == 0) ? +1 : -1;  // +q direction first
        const bool flexion = (j == 0) ? sign > 0 : sign < 0;  // hip flexion +, knee flexion -
        if (flexion != (d == 0)) continue;
        for (size_t k = static_cast<size_t>(blk.t_start / kDt);
             k < static_cast<size_t>((blk.t_start + 2 * blk.ramp + blk.hold) / kDt); ++k) {
          y.push_back(tau[k]);
          yhat.push_back(IsometricTorque(j, c.fit[j].alpha, r.le[k]));
        }
      }
      c.dir[j][d] = Quality(y, yhat);
    }
  }
  return c;
}

TEST(EmgCalibration, IsometricAlphaRecoversGroundTruthAndMatchesTable6) {
  // Table 6 gives means over 10 subjects (R^2 0.951-0.976, NRMS 5.03-8.12 %, SDs 0.012-0.019 and
  // 1.5-2.4 %): compare the mean over 3 virtual subjects x 2 joints x 2 directions with those, and
  // each fit with the paper's worst mean minus 2 SD.
  const char* joint[] = {"hip", "knee"};
  const char* dir[] = {"flexion", "extension"};
  double r2_sum = 0, nrms_sum = 0;
  int n = 0;
  for (uint64_t seed : {1u, 2u, 3u}) {
    const Calibrated c = CalibrateIsometric(seed);
    for (int j = 0; j < 2; ++j) {
      for (int d = 0; d < 2; ++d) {
        std::printf("[calib] seed %d %s %s: R^2 %.3f NRMS %.2f %%\n", static_cast<int>(seed), joint[j],
                    dir[d], c.dir[j][d].r2, c.dir[j][d].nrms_pct);
        r2_sum += c.dir[j][d].r2;
        nrms_sum += c.dir[j][d].nrms_pct;
        ++n;
        EXPECT_GE(c.dir[j][d].r2, 0.951 - 2 * 0.019 - 0.05);
        EXPECT_LE(c.dir[j][d].nrms_pct, 8.12 + 2 * 2.37);
      }
      // Synergists (same action at joint j) are co-active in each contraction, so the fit separates
      // them only through their independent envelope noise and crosstalk: their SUM is what the
      // torque pins down (within 10 %); each alone within 35 % (seed 3's weak hip ST, 50 N m beside
      // a GMAX of 101: +28 %, its GMAX -22 %, their sum -5 %).
      double fitted_sum[2] = {0, 0}, expected_sum[2] = {0, 0};
      for (int m = 0; m < kNumMuscles; ++m) {
        const double truth = c.truth.alpha(m, j);
        if (truth == 0) continue;
        // The paper's MVC (mean of the highest peaks) sits above the plateau by the envelope's
        // ripple, so the fitted alpha is the torque at the PEAK envelope: truth x peak/plateau.
        const double expected = truth * c.peak_over_plateau[m];
        std::printf("[calib] seed %d %s alpha_%s: fitted %.1f, truth %.1f x MVC peak/plateau %.3f = %.1f "
                    "N m (%+.1f %%)\n", static_cast<int>(seed), joint[j], MuscleName(MuscleAt(m)),
                    c.fit[j].alpha[m], truth, c.peak_over_plateau[m], expected,
                    100 * (c.fit[j].alpha[m] / expected - 1));
        EXPECT_NEAR(c.fit[j].alpha[m], expected, 0.35 * expected);
        const int side = ActionSign(MuscleAt(m), j) > 0 ? 0 : 1;
        fitted_sum[side] += c.fit[j].alpha[m];
        expected_sum[side] += expected;
      }
      for (int side = 0; side < 2; ++side) {
        std::printf("[calib] seed %d %s synergists acting along %cq: summed alpha %.1f vs %.1f N m (%+.1f %%)\n",
                    static_cast<int>(seed), joint[j], side ? '-' : '+', fitted_sum[side], expected_sum[side],
                    100 * (fitted_sum[side] / expected_sum[side] - 1));
        EXPECT_NEAR(fitted_sum[side], expected_sum[side], 0.10 * expected_sum[side]);
      }
    }
  }
  std::printf("[calib] isometric mean R^2 %.3f (Table 6: 0.951-0.976), mean NRMS %.2f %% (5.03-8.12 %%)\n",
              r2_sum / n, nrms_sum / n);
  EXPECT_GE(r2_sum / n, 0.95);
  EXPECT_LE(nrms_sum / n, 8.0);
}

// One switch per EMG-side error source of the dynamic calibration (the error budget of Table 7).
struct Knobs {
  const char* name = "twin as shipped";
  bool emd = true;            // electromechanical delay (EMG leads force by ~40 ms)
  bool crosstalk = true;      // VM<->RF, ST<->GAS, GMAX<->ST crosstalk
  bool cocontraction_kd = true;  // co-contraction K, D terms that HJ15 eq. 26-27 lack
  bool sensor_noise = true;   // 0.3 N m torque-sensor noise
  bool baseline = true;       // relaxed EMG baseline (electrode noise)
  double envelope_hz = 2.0;   // linear-envelope cut-off (Hz)
  bool oracle_le = false;     // LE = the true electrical activation (no EMG at all)
  double gait_kd = 0;         // subject's velocity gain in the gait (< 0: the free-limb default 15 / 4;
                              // 0 as the runner: the exoskeleton imposes the motion)
  double gait_gain = 1.8;     // exaggeration of the gait pattern (as exowheel_emg_dynamic.yaml)
  bool seated_rest = false;   // co-contraction stiffness about the seated hanging posture (sim default)
  bool rest_subtracted = false;  // processing: relaxed envelope level removed before normalizing
};

// Identified (= the twin's truth, Table 4 S1), De Leva and Dempster (sim/anthropometry from S1's
// weight and lengths, Table 4 rule) lumped models, with the known exoskeleton and Riener passive.
std::vector<LegParams> Table7Models() {
  const Subject s1 = PresetSubject("S1");
  LegParams id = SubjectLegParams(s1);
  id.passive = PassiveModel::kRiener1999;
  LegParams dl = id, dp = id;
  dl.human = Table4AnthropometricLumped(AnthropometricModel::kDeLeva, s1.weight, s1.L1, s1.L2);
  dp.human = Table4AnthropometricLumped(AnthropometricModel::kDempster, s1.weight, s1.L1, s1.L2);
  return {id, dl, dp};
}

struct DynamicOutcome {
  double r2[3][2];          // [identified, De Leva, Dempster][hip, knee]
  double beta[3][2], gamma[3][2];
  double rms_tau_m[2];      // RMS of the true muscular torque over the active gait, N m
  double rms_model_err[3][2];  // RMS of the model's error on tau_M (HJ15 eq. 9), N m
};

// The whole pipeline (MVC, isometric alpha, exaggerated gait, beta/gamma with 3 models) with knobs.
DynamicOutcome RunPipeline(const Knobs& kb, uint64_t seed) {
  MuscleParams truth = DrawMuscleParams(seed);
  if (!kb.emd) truth.emd = 0;
  if (!kb.cocontraction_kd) truth.cK.setZero(), truth.cD.setZero();
  const Eigen::Vector2d mean(0.2, -0.5);  // mean gait posture (rad)
  const SyntheticEmgConfig saved = g_cfg;
  if (!kb.crosstalk) g_cfg.crosstalk.setIdentity();
  if (!kb.baseline) g_cfg.baseline_rms.setConstant(1e-9);
  const double noise_sd = kb.sensor_noise ? 0.3 : 0.0;
  // MVC and isometric alpha as in the Table 6 test.
  MuscleVec rest = MuscleVec::Zero();
  MuscleVec mvc = MeasureMvc(truth, seed * 100, nullptr, kb.envelope_hz, &rest);
  if (!kb.rest_subtracted || kb.oracle_le) rest.setZero();
  if (kb.oracle_le) mvc.setOnes();
  MuscleRng noise(MixSeed(seed ^ 0x5e));
  AlphaFit fit[2];
  for (int j = 0; j < 2; ++j) {
    ContractionProgramme prog = IsometricProgramme(j, 8, 0.1, 0.5, 0.1, seed + j);
    MuscleParams held = truth;  // co-contraction stiffens about the held pose (runner.cc)
    if (!kb.seated_rest) held.q_rest = truth.theta_c;
    Record r = RunTrial(held, prog, prog.duration() + 1, [&](double, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
      q = truth.theta_c;
      qd.setZero();
    }, seed * 100 + 10 + j, kb.envelope_hz, kb.oracle_le);
    Normalize(r, mvc, rest);
    std::vector<double> tau;
    for (const auto& t : r.tau) tau.push_back(t[j] + noise_sd * noise.Normal());
    fit[j] = FitIsometricAlpha(j, r.le, tau);
  }
  // Gait on the exoskeleton: 2 s stride (2 km/h), relaxed 5 s then exaggerated (section 4.3).
  if (!kb.seated_rest) truth.q_rest = mean;
  const double w = 2 * kPi * 0.5;
  auto kin = [&](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd) {
    q = mean + Eigen::Vector2d(0.35 * std::sin(w * t), 0.45 * std::sin(w * t - 1.0));
    qd = Eigen::Vector2d(0.35 * w * std::cos(w * t), 0.45 * w * std::cos(w * t - 1.0));
  };
  auto kin_acc = [&](double t) { return Eigen::Vector2d(-0.35 * w * w * std::sin(w * t), -0.45 * w * w * std::sin(w * t - 1.0)); };
  TrackingGains gains;
  if (kb.gait_kd >= 0) gains.kd.setConstant(kb.gait_kd);  // else the free-limb default
  ExaggeratedGait gait(truth, [&](double t, Eigen::Vector2d& q, Eigen::Vector2d& qd, Eigen::Vector2d& qdd) {
    kin(t, q, qd);
    qdd = kin_acc(t);
  }, mean, kb.gait_gain, 5.0, 0.02, gains);
  Record r = RunTrial(truth, gait, 25.0, kin, seed * 100 + 50, kb.envelope_hz, kb.oracle_le);
  Normalize(r, mvc, rest);
  g_cfg = saved;
  const std::vector<LegParams> models = Table7Models();
  MuscleRng sn(MixSeed(seed ^ 0x77));
  DynamicOutcome o{};
  const size_t k0 = static_cast<size_t>(5.5 / kDt);
  for (int j = 0; j < 2; ++j) {
    double s2 = 0;
    for (size_t k = k0; k < r.tau.size(); ++k) s2 += r.tau[k][j] * r.tau[k][j];
    o.rms_tau_m[j] = std::sqrt(s2 / (r.tau.size() - k0));
  }
  std::vector<Eigen::Vector2d> tau_S;
  for (size_t k = 0; k < r.tau.size(); ++k)  // sensor (HJ15 eq. 8), the identified model as the plant
    tau_S.push_back(r.tau[k] - ActuatorTorque(models[0], r.q[k], r.qd[k], kin_acc(k * kDt)) +
                    noise_sd * Eigen::Vector2d(sn.Normal(), sn.Normal()));
  for (int mi = 0; mi < 3; ++mi) {
    for (int j = 0; j < 2; ++j) {
      std::vector<MuscleVec> le;
      std::vector<double> q, qd, tau_M;
      double e2 = 0;
      for (size_t k = k0; k < r.tau.size(); ++k) {
        const Eigen::Vector2d tm = tau_S[k] + ActuatorTorque(models[mi], r.q[k], r.qd[k], kin_acc(k * kDt));  // HJ15 eq. 9
        e2 += (tm[j] - r.tau[k][j]) * (tm[j] - r.tau[k][j]);
        le.push_back(r.le[k]);
        q.push_back(r.q[k][j]);
        qd.push_back(r.qd[k][j]);
        tau_M.push_back(tm[j]);
      }
      const BetaGammaFit f = FitDynamicBetaGamma(j, fit[j].alpha, truth.theta_c[j], le, q, qd, tau_M);
      o.r2[mi][j] = f.quality.r2;
      o.beta[mi][j] = f.beta;
      o.gamma[mi][j] = f.gamma;
      o.rms_model_err[mi][j] = std::sqrt(e2 / le.size());
    }
  }
  return o;
}

TEST(EmgCalibration, DynamicBetaGammaAndTheTable7Pattern) {
  const DynamicOutcome o = RunPipeline(Knobs(), 4);
  const char* joint[] = {"hip", "knee"};
  const MuscleParams truth = DrawMuscleParams(4);
  // Table 7 identified rows: mean - 2 SD (0.935 - 2 x 0.028, 0.924 - 2 x 0.034).
  const double r2_min[2] = {0.935 - 2 * 0.028, 0.924 - 2 * 0.034};
  for (int j = 0; j < 2; ++j) {
    std::printf("[calib] %s R^2 identified %.3f, De Leva %.3f, Dempster %.3f (Table 7: %s); gamma %.2fe-3 "
                "(truth %.2fe-3) /(deg/s); beta %.2fe-3 / %.2fe-3 / %.2fe-3 /deg\n", joint[j], o.r2[0][j],
                o.r2[1][j], o.r2[2][j], j == 0 ? "0.935, 0.884, 0.879" : "0.924, 0.877, 0.872",
                1e3 * o.gamma[0][j] / kDegPerRad, 1e3 * truth.gamma[j] / kDegPerRad, 1e3 * o.beta[0][j] / kDegPerRad,
                1e3 * o.beta[1][j] / kDegPerRad, 1e3 * o.beta[2][j] / kDegPerRad);
    EXPECT_GE(o.r2[0][j], r2_min[j]);
    // gamma also absorbs the envelope's lead over the force (zero-phase envelope, 30-50 ms EMD).
    EXPECT_GT(o.gamma[0][j], 0.5 * truth.gamma[j]);
    EXPECT_LT(o.gamma[0][j], 3.0 * truth.gamma[j]);
  }
  // Table 7's ranking holds at the hip, where the anthropometric error on tau_M varies with the hip
  // angle. At the knee the error is mostly a constant (Y2 = 0 instead of 0.42 kg m) that the beta
  // column (E + F)(q - q_c) absorbs while the knee co-contracts (see exowheel_emg_dynamic.yaml).
  EXPECT_GT(o.r2[0][0], o.r2[1][0]);
  EXPECT_GT(o.r2[0][0], o.r2[2][0]);
  EXPECT_LT(o.beta[1][1], o.beta[0][1]);  // the absorbed offset shows as a lower knee beta, as Table 7
  EXPECT_LT(o.beta[2][1], o.beta[0][1]);
}

// The error budget of the twin's dynamic R^2 (Table 7): one EMG-side source switched off at a time,
// next to the torque error the anthropometric models induce on tau_M (HJ15 eq. 9) over the same gait.
TEST(EmgCalibration, Table7ErrorBudget) {
  std::vector<Knobs> rows(13);
  rows[1].name = "no electromechanical delay"; rows[1].emd = false;
  rows[2].name = "no crosstalk"; rows[2].crosstalk = false;
  rows[3].name = "no co-contraction K, D"; rows[3].cocontraction_kd = false;
  rows[4].name = "no torque-sensor noise"; rows[4].sensor_noise = false;
  rows[5].name = "no EMG baseline"; rows[5].baseline = false;
  rows[6].name = "rest level subtracted"; rows[6].rest_subtracted = true;
  rows[7].name = "envelope 6 Hz"; rows[7].envelope_hz = 6.0;
  rows[8].name = "oracle LE (true activation)"; rows[8].oracle_le = true;
  rows[9].name = "free-limb kd 15 / 4 (before)"; rows[9].gait_kd = -1;
  rows[10].name = "K about seated posture (before)"; rows[10].seated_rest = true;
  rows[11].name = "gain 1.3 (before)"; rows[11].gait_gain = 1.3;
  rows[12].name = "all three (before)"; rows[12].gait_kd = -1; rows[12].seated_rest = true;
  rows[12].gait_gain = 1.3;
  for (const Knobs& kb : rows) {
    const DynamicOutcome o = RunPipeline(kb, 4);
    std::printf("[budget] %-32s R^2 hip %.3f / %.3f / %.3f  knee %.3f / %.3f / %.3f  (identified / De Leva / "
                "Dempster)\n", kb.name, o.r2[0][0], o.r2[1][0], o.r2[2][0], o.r2[0][1], o.r2[1][1], o.r2[2][1]);
    if (&kb == &rows[0] || &kb == &rows[12])
      for (int j = 0; j < 2; ++j)
        std::printf("[budget] %s: RMS tau_M %.2f N m; model error on tau_M: identified %.2f, De Leva %.2f, "
                    "Dempster %.2f N m\n", j ? "knee" : "hip", o.rms_tau_m[j], o.rms_model_err[0][j],
                    o.rms_model_err[1][j], o.rms_model_err[2][j]);
  }
}

TEST(EmgCalibration, QualityDefinitions) {
  const std::vector<double> y{0, 1, 2, 3, 4}, yhat{0, 1, 2, 3, 5};
  const FitQuality q = Quality(y, yhat);
  EXPECT_NEAR(q.r2, 1 - 1.0 / 10.0, 1e-12);
  EXPECT_NEAR(q.nrms_pct, 100 * std::sqrt(1.0 / 5) / 4, 1e-12);
}

}  // namespace
}  // namespace exotwin
