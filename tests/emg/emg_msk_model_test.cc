// The musculoskeletal form of the EMG-driven moment (emg/emg_msk_model.h): a synthetic Hill-type law
// with known parameters (strengths, tendon slack and optimal fibre lengths, A, delay, remainder
// terms) is recovered within 10 % from one gait-like trial and predicts another trial of the same law;
// the calibrated state ranges and the reachable share behave as their definitions say.
#include "emg/emg_msk_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "core/rng.h"
#include "emg/emg_torque_model.h"
#include "core/error.h"
#include "tests/emg/gait_trial.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

// The law: strengths, lengths, A, delay and remainder away from the nominal values, inside the bounds.
struct Law {
  double strength[5] = {1.3, 0.8, 1.1, 0.7, 1.2};
  double ts_change[5] = {0.03, -0.02, 0.04, -0.03, 0.02};   // fraction of the nominal l_ts
  double lo_change[5] = {-0.02, 0.01, 0.02, -0.015, 0.0};   // fraction of the nominal l_opt
  double A = -1.6, delay = 0.045, twitch = 0.0;
  double beta[2] = {-15, 8}, gamma[2] = {-1.5, 1.0}, offset[2] = {4, -3};
  double passive_scale[2] = {0.6, 1.4};  // x Riener & Edrich 1999
  double noise = 1.0;  // N m
  // The unrecorded gluteus maximus (the trial's missing muscle): strength x synergy weight per source
  // channel (EmgMskMuscle::synthesized), 0: none.
  double gmax[5] = {0, 0, 0, 0, 0};
};

// Writes the law's moments (plus white noise) into r.tau and returns the true model.
EmgMskModel ApplyLaw(const Law& law, EmgRecording* r, uint64_t seed) {
  // The nominal muscles as FitEmgMsk builds them (no fit: a copy of its set-up).
  EmgMskModel m;
  m.present = true;
  m.delay = law.delay, m.twitch = law.twitch, m.a_shape = law.A;
  for (size_t c = 0; c < r->channels.size(); ++c) {
    EmgMskMuscle x;
    x.channel = r->channels[c], x.muscle = r->muscle[c];
    x.nominal = ScaledMusculotendon(x.muscle, GenericMusculotendon(x.muscle));
    MusculotendonParams own;
    if (GenericMusculotendon(x.channel, &own)) x.nominal.f_max = own.f_max;
    x.strength = law.strength[c];
    x.l_ts = x.nominal.l_ts * (1 + law.ts_change[c]);
    x.l_opt = x.nominal.l_opt * (1 + law.lo_change[c]);
    x.fibre_lo = x.velocity_lo = -1e9, x.fibre_hi = x.velocity_hi = 1e9;
    m.muscles.push_back(x);
  }
  for (size_t c = 0; c < r->channels.size(); ++c) {
    if (law.gmax[c] == 0) continue;
    EmgMskMuscle x;
    x.channel = r->channels[c], x.muscle = Muscle::kGMAX, x.synthesized = true;
    x.nominal = ScaledMusculotendon(Muscle::kGMAX, GenericMusculotendon(Muscle::kGMAX));
    x.l_ts = x.nominal.l_ts, x.l_opt = x.nominal.l_opt, x.strength = law.gmax[c];
    x.fibre_lo = x.velocity_lo = -1e9, x.fibre_hi = x.velocity_hi = 1e9;
    m.muscles.push_back(x);
  }
  for (int j = 0; j < 2; ++j)
    m.beta[j] = law.beta[j], m.gamma[j] = law.gamma[j], m.offset[j] = law.offset[j], m.passive_scale[j] = law.passive_scale[j];
  const EmgMskSeries s = MskSeries(m, *r);
  NormalRng<NormalPolar> rng(seed * 7919);
  for (int j = 0; j < 2; ++j) {
    r->tau[j] = s.tau[j];
    for (double& v : r->tau[j]) v += law.noise * rng.Normal();
  }
  return m;
}

// Two trials of one law (seeds `seed` and seed + 1): a to calibrate on, b to predict.
struct TwoTrials {
  EmgRecording a, b;
  EmgMskModel truth;  // of a
};
TwoTrials TrialsOf(const Law& law, uint64_t seed) {
  NormalRng<NormalPolar> ra(seed), rb(seed + 1);
  TwoTrials t{GaitEnvelopesAndAngles(ra, "gait trial " + std::to_string(seed)),
              GaitEnvelopesAndAngles(rb, "gait trial " + std::to_string(seed + 1)), {}};
  t.truth = ApplyLaw(law, &t.a, seed);
  ApplyLaw(law, &t.b, seed + 1);
  return t;
}

TEST(EmgMskModel, SyntheticHillLawIsRecoveredWithin10Percent) {
  const Law law;
  TwoTrials trials = TrialsOf(law, 31);
  const EmgRecording &a = trials.a, &b = trials.b;
  const EmgMskModel& truth = trials.truth;
  EmgMskFitOptions opt;
  opt.cross_validate = false;
  opt.synthesize_missing = false;  // this law has no unrecorded muscle (the next test has one)
  const EmgMskModel fit = FitEmgMsk({&a}, law.twitch, opt);
  ASSERT_TRUE(fit.present);
  {
    double sf = 0, st = 0;
    for (int j = 0; j < 2; ++j) {
      const auto pf = MskSeries(fit, a).tau[j], pt = MskSeries(truth, a).tau[j];
      for (size_t i = 0; i < pf.size(); ++i) sf += std::pow(a.tau[j][i] - pf[i], 2), st += std::pow(a.tau[j][i] - pt[i], 2);
    }
    std::printf("SSE fit %.1f truth %.1f\n", sf, st);
    EXPECT_LE(sf, 1.001 * st) << "the search stops short of the minimum";
  }
  ASSERT_EQ(fit.muscles.size(), truth.muscles.size());
  std::printf("delay %.3f (truth %.3f), A %.2f (truth %.2f)\n", fit.delay, law.delay, fit.a_shape, law.A);
  EXPECT_NEAR(fit.delay, law.delay, 0.1 * law.delay);
  EXPECT_NEAR(fit.a_shape, law.A, 0.1 * std::abs(law.A));
  for (size_t c = 0; c < fit.muscles.size(); ++c) {
    const EmgMskMuscle &f = fit.muscles[c], &t = truth.muscles[c];
    std::printf("%-10s strength %.3f (truth %.3f), l_ts %.4f (truth %.4f, nominal %.4f), l_opt %.4f (truth %.4f)\n",
                f.channel.c_str(), f.strength, t.strength, f.l_ts, t.l_ts, t.nominal.l_ts, f.l_opt, t.l_opt);
    EXPECT_NEAR(f.strength, t.strength, 0.1 * t.strength) << f.channel;
    // Lengths: the bounds are +-5 % (l_ts) and +-2.5 % (l_opt) of the nominal value, so 10 % of the
    // value would say nothing: l_ts within 1 % (a tenth of its band); l_opt within 3 %: it moves the
    // moment least, and the fit's sum of squares is already below the truth's (the rest is noise).
    EXPECT_NEAR(f.l_ts, t.l_ts, 0.01 * t.l_ts) << f.channel;
    EXPECT_NEAR(f.l_opt, t.l_opt, 0.03 * t.l_opt) << f.channel;
  }
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(fit.beta[j], law.beta[j], 0.1 * std::abs(law.beta[j]));
    std::printf("%s: passive_scale %.3f (truth %.3f)\n", j ? "knee" : "hip", fit.passive_scale[j], law.passive_scale[j]);
    EXPECT_NEAR(fit.passive_scale[j], law.passive_scale[j], 0.1 * law.passive_scale[j]);
    const double r2 = R2(b.tau[j], MskSeries(fit, b).tau[j]);
    std::printf("%s: R^2 on another trial of the law %.4f\n", j ? "knee" : "hip", r2);
    EXPECT_GE(r2, 0.97);
  }
}


// An unrecorded gluteus maximus driven by a known combination of two recorded channels (the synergy
// extrapolation of EmgMskMuscle): its weights are recovered within 10 %, the other sources' stay near
// zero, and another trial of the law is predicted at the hip; without the synthesized muscle the
// recorded muscles and the remainder carry the gluteus only in part (measured: R^2 0.967 against 0.999).
TEST(EmgMskModel, UnrecordedGluteusIsSynthesizedFromTheRecordedExcitations) {
  Law law;
  law.gmax[0] = 0.9;  // vas_lat_r: the weight-acceptance burst (Neptune et al. 2009's first module)
  law.gmax[2] = 1.2;  // semimem_r: the late-swing burst
  TwoTrials trials = TrialsOf(law, 71);
  const EmgRecording &a = trials.a, &b = trials.b;
  const EmgMskModel& truth = trials.truth;
  EmgMskFitOptions opt;
  opt.cross_validate = false;
  const EmgMskModel fit = FitEmgMsk({&a}, law.twitch, opt);
  opt.synthesize_missing = false;
  const EmgMskModel without = FitEmgMsk({&a}, law.twitch, opt);
  ASSERT_EQ(fit.muscles.size(), 10u);
  ASSERT_EQ(without.muscles.size(), 5u);
  for (size_t c = 5; c < 10; ++c) {
    const EmgMskMuscle& f = fit.muscles[c];
    const double w = law.gmax[c - 5];
    std::printf("%-22s strength %.4f (truth %.4f)\n", f.Label().c_str(), f.strength, w);
    EXPECT_TRUE(f.synthesized);
    EXPECT_EQ(f.muscle, Muscle::kGMAX);
    if (w > 0) EXPECT_NEAR(f.strength, w, 0.1 * w) << f.Label();
    else EXPECT_LT(f.strength, 0.05) << f.Label();
  }
  for (size_t c = 0; c < 5; ++c) EXPECT_NEAR(fit.muscles[c].strength, truth.muscles[c].strength, 0.1 * truth.muscles[c].strength);
  // The synthesized muscle acts at the hip only (glut_max2 does not cross the knee).
  const EmgMskSeries sb = MskSeries(fit, b);
  const double r2_hip = R2(b.tau[0], sb.tau[0]), r2_without = R2(b.tau[0], MskSeries(without, b).tau[0]);
  std::printf("hip R^2 on another trial: %.4f synthesized, %.4f without\n", r2_hip, r2_without);
  EXPECT_GE(r2_hip, 0.97);
  EXPECT_LT(r2_without, r2_hip - 0.02);
  // The synthesized activation times strength stays a muscle's: at most kStrengthHi.
  EXPECT_LE(fit.synthesized_peak, kStrengthHi);
  EXPECT_GT(fit.synthesized_peak, 0.0);
}


void WriteText(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

// A calibration of both forms on a trial of the Hill law, the knee in the musculoskeletal form.
EmgTorqueModel BothForms(const EmgRecording& a) {
  EmgTorqueModel m = FitEmgModel(EmgModelSpec{}, {&a});
  EmgMskFitOptions opt;
  opt.cross_validate = false;
  m.msk = FitEmgMsk({&a}, 0, opt);
  m.msk_form[1] = true;
  return m;
}

// EMGMODEL.yaml carries the form per joint and every muscle's parameters with bounds and sources; read
// back, it predicts the same moments.
TEST(EmgMskModel, ModelFileCarriesTheFormsAndTheMuscles) {
  const Law law;
  NormalRng<NormalPolar> ra(41);
  EmgRecording a = GaitEnvelopesAndAngles(ra, "gait trial 41");
  ApplyLaw(law, &a, 41);
  const EmgTorqueModel m = BothForms(a);
  const testing::ScopedTempDir dir("emgmsk");
  const std::string path = dir.path() + "/m.yaml";
  const std::string text = EmgModelYaml(m, {"test"});
  for (const char* key : {"forms: {hip: linear, knee: musculoskeletal}", "strength: {value:", "bounds: [0.5, 1.5]",
                          "tendon_slack_length: {value:", "optimal_fibre_length: {value:", "source:", "gait2392 vas_int"})
    EXPECT_NE(text.find(key), std::string::npos) << key;
  WriteText(path, text);
  const EmgTorqueModel back = ReadEmgModel(path);
  EXPECT_FALSE(back.msk_form[0]);
  EXPECT_TRUE(back.msk_form[1]);
  ASSERT_EQ(back.msk.muscles.size(), m.msk.muscles.size());
  EXPECT_NE(text.find("synthesized: true"), std::string::npos);  // the trial's unrecorded gluteus
  for (size_t c = 0; c < m.msk.muscles.size(); ++c) {
    EXPECT_EQ(back.msk.muscles[c].synthesized, m.msk.muscles[c].synthesized);
    EXPECT_NEAR(back.msk.muscles[c].strength, m.msk.muscles[c].strength, 1e-9);
    EXPECT_NEAR(back.msk.muscles[c].l_ts, m.msk.muscles[c].l_ts, 1e-9);
  }
  for (int j = 0; j < 2; ++j) {
    const std::vector<double> x = PredictMoment(m, a, j), y = PredictMoment(back, a, j);
    for (size_t i = 0; i < x.size(); i += 37) EXPECT_NEAR(x[i], y[i], 1e-6 * (1 + std::abs(x[i]))) << j;
  }
  // A parameter outside its physiological bounds, a recorded muscle with a synthesized term's lower
  // bound (0), a synthesized flag that is not a boolean: exit 2 naming the file and the key.
  auto replaced = [&](const std::string& from, const std::string& upto, const std::string& to) {
    std::string bad = text;
    const size_t at = bad.find(from);
    bad.replace(at, bad.find(upto, at) - at, to);
    return bad;
  };
  const std::pair<std::string, std::string> bad[] = {
      {replaced("strength: {value: ", ",", "strength: {value: 2.5"), "musculoskeletal.muscles[0].strength.value"},
      {replaced("bounds: [0.5, 1.5]", "]", "bounds: [0, 1.5"), "musculoskeletal.muscles[0].strength.bounds[0]"},
      {replaced("synthesized: true", "\n", "synthesized: maybe"), ".synthesized"},
  };
  for (const auto& [file, key] : bad) {
    WriteText(path, file);
    try {
      ReadEmgModel(path);
      ADD_FAILURE() << "accepted " << key;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// Outside the muscles' calibrated states the knee falls back to the linear form, sample by sample, and
// says how often; inside it is the musculoskeletal form's moment.
TEST(EmgMskModel, OutsideTheCalibratedStatesTheLinearFormStandsIn) {
  const Law law;
  NormalRng<NormalPolar> ra(51), rb(52);
  EmgRecording a = GaitEnvelopesAndAngles(ra, "gait trial 51"), b = GaitEnvelopesAndAngles(rb, "gait trial 52");
  ApplyLaw(law, &a, 51);
  for (size_t i = 0; i < b.size(); ++i) b.q[1][i] = -0.65 + 1.4 * (b.q[1][i] + 0.65), b.qd[1][i] *= 1.4;  // a wider knee
  ApplyLaw(law, &b, 52);
  const EmgTorqueModel m = BothForms(a);
  const EmgPrediction p = PredictMoments(m, b);
  const std::vector<double> lin = PredictLinearMoment(m, b, 1);
  const EmgMskSeries s = MskSeries(m.msk, b);
  EXPECT_GT(p.fallback_share[1], 0.05);
  EXPECT_LT(p.fallback_share[1], 0.95);
  EXPECT_EQ(p.fallback_share[0], 0.0);  // the hip is in the linear form
  for (size_t i = 0; i < b.size(); ++i) {
    EXPECT_EQ(p.fallback[1][i], s.outside[1][i]);
    EXPECT_DOUBLE_EQ(p.tau[1][i], s.outside[1][i] ? lin[i] : s.tau[1][i]);
  }
  // On the calibration trial itself nothing falls back.
  EXPECT_EQ(PredictMoments(m, a).fallback_share[1], 0.0);
}


// A map file's musculoskeletal section: the joints a channel's muscle crosses and its strength bounds;
// a joint its path does not cross, a biarticular muscle given one joint, bounds outside the
// calibration's, a channel not mapped: exit 2 naming the file and the key. The narrowed bounds hold.
TEST(EmgMskModel, MapFileBoundsAndJointsAreChecked) {
  const testing::ScopedTempDir dir("emgmskmap");
  const std::string path = dir.path() + "/map.yaml";
  const std::string head = "muscles: {VM: [vas_lat_r], RF: [rect_fem_r], ST: [semimem_r, bifemlh_r], GAS: [med_gas_r]}\n";
  WriteText(path, head + "musculoskeletal:\n  rect_fem_r: {joints: [hip, knee], strength: [0.9, 1.1]}\n  vas_lat_r: {joints: [knee]}\n");
  const MuscleMap ok = ReadMuscleMap(path);
  ASSERT_EQ(ok.strength_bounds.count("rect_fem_r"), 1u);
  EXPECT_EQ(ok.strength_bounds.at("rect_fem_r")[0], 0.9);
  const std::pair<std::string, std::string> bad[] = {
      {"  vas_lat_r: {joints: [hip, knee]}\n", "musculoskeletal.vas_lat_r.joints"},       // the vasti do not cross the hip
      {"  rect_fem_r: {joints: [knee]}\n", "musculoskeletal.rect_fem_r.joints"},          // RF crosses the hip too
      {"  rect_fem_r: {strength: [0.2, 1.0]}\n", "musculoskeletal.rect_fem_r.strength[0]"},
      {"  rect_fem_r: {strength: [1.0, 4.0]}\n", "musculoskeletal.rect_fem_r.strength[1]"},
      {"  soleus_r: {joints: [knee]}\n", "musculoskeletal.soleus_r"},                     // not mapped
      {"  vas_lat_r: {joints: [ankle]}\n", "musculoskeletal.vas_lat_r.joints"},
      {"  vas_lat_r: {joints: [knee]}\ncoordinates: {hip: hip_flexion_r, knee: knee_angle_r, ankle: [a]}\n",
       "coordinates.ankle"},
  };
  for (const auto& b : bad) {
    WriteText(path, head + "musculoskeletal:\n" + b.first);
    try {
      ReadMuscleMap(path);
      ADD_FAILURE() << "accepted " << b.first;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(b.second), std::string::npos) << e.what();
    }
  }
  // The narrowed bounds hold in the calibration: the law's vas_lat strength 1.3 held at 1.1.
  const Law law;
  NormalRng<NormalPolar> ra(61);
  EmgRecording a = GaitEnvelopesAndAngles(ra, "gait trial 61");
  ApplyLaw(law, &a, 61);
  EmgMskFitOptions opt;
  opt.cross_validate = false;
  opt.strength_bounds["vas_lat_r"] = {0.9, 1.1};
  const EmgMskModel m = FitEmgMsk({&a}, 0, opt);
  EXPECT_NEAR(m.muscles[0].strength, 1.1, 1e-9);
  EXPECT_EQ(m.muscles[0].strength_hi, 1.1);
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

const std::string kDir = std::string(EXOTWIN_SOURCE_DIR) + "/../shared/data/real_human/ceinms_lowerlimb_walk36";

// The development trial (shared/data/real_human): every calibrated parameter inside its bounds, the
// form cross-validated, the state ranges holding every calibration sample.
TEST(EmgMskModel, DevelopmentTrialStaysInsideTheBounds) {
  if (!std::ifstream(kDir + "/emgFilt.sto")) GTEST_SKIP() << "shared/data not beside the project";
  const EmgRecording r = ReadEmgRecording(kDir + "/emgFilt.sto", kDir + "/ik.sto", kDir + "/id.sto", DefaultMuscleMap());
  // The ankle angle is read (ankle_angle_r: -15.0 .. 13.1 deg in the file).
  ASSERT_EQ(r.q_ankle.size(), r.size());
  const auto ar = std::minmax_element(r.q_ankle.begin(), r.q_ankle.end());
  EXPECT_NEAR(*ar.first * 180 / M_PI, -15.02, 0.05);
  EXPECT_NEAR(*ar.second * 180 / M_PI, 13.14, 0.05);
  const EmgMskModel m = FitEmgMsk({&r}, 0.065);  // the twitch emg-fit's loop names on this trial
  EXPECT_TRUE(m.elastic_tendon);
  std::printf("delay %.3f A %.2f\n", m.delay, m.a_shape);
  for (const EmgMskMuscle& x : m.muscles)
    std::printf("%-20s strength %.3f l_ts %.4f (nom %.4f) l_opt %.4f (nom %.4f) fibre %.2f..%.2f v %.3f..%.3f\n",
                x.Label().c_str(), x.strength, x.l_ts, x.nominal.l_ts, x.l_opt, x.nominal.l_opt, x.fibre_lo, x.fibre_hi,
                x.velocity_lo, x.velocity_hi);
  for (int j = 0; j < 2; ++j)
    std::printf("%s: r2_cv %.3f rms_cv %.2f r2_fit %.3f reachable %.3f (recorded activation %.3f) beta %.2f gamma %.2f "
                "offset %.2f\n", j ? "knee" : "hip", m.r2_cv[j], m.rms_cv[j], m.r2_fit[j], m.reachable_share[j],
                m.reachable_share_recorded[j], m.beta[j], m.gamma[j], m.offset[j]);
  EXPECT_GE(m.delay, 0.01);
  EXPECT_LE(m.delay, 0.1);
  EXPECT_GT(m.a_shape, -3.0);
  EXPECT_LT(m.a_shape, 0.0);
  std::printf("synthesized GMAX: peak activation x strength %.3f\n", m.synthesized_peak);
  EXPECT_LE(m.synthesized_peak, kStrengthHi);
  for (const EmgMskMuscle& x : m.muscles) {
    EXPECT_GE(x.strength, (x.synthesized ? kSynthesizedStrengthLo : kStrengthLo) - 1e-12);
    EXPECT_LE(x.strength, kStrengthHi + 1e-12);
    EXPECT_LE(std::abs(x.l_ts / x.nominal.l_ts - 1), kTendonSlackChange + 1e-12);
    EXPECT_LE(std::abs(x.l_opt / x.nominal.l_opt - 1), kOptimalFibreChange + 1e-12);
    EXPECT_LT(x.fibre_lo, x.fibre_hi);
  }
  const EmgMskSeries s = MskSeries(m, r);
  for (int j = 0; j < 2; ++j) {
    EXPECT_GT(m.r2_cv[j], 0.6);
    EXPECT_GT(m.reachable_share[j], 0.0);
    EXPECT_LE(m.reachable_share[j], 1.0);
    // Activated as recorded the muscles reach less than fully activated (activation <= 1).
    EXPECT_GT(m.reachable_share_recorded[j], 0.0);
    EXPECT_LE(m.reachable_share_recorded[j], m.reachable_share[j] + 1e-12);
    for (char o : s.outside[j]) EXPECT_FALSE(o);  // the calibration's own samples are inside
  }
}

}  // namespace
}  // namespace exotwin
