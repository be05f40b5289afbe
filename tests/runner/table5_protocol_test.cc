// The Table 5 protocol end to end on 2 subjects with short trials (scenarios/table5_protocol.h):
// identification through the closed loop recovers the hidden truth, and the identified parameters
// predict the relaxed-gait torque better than both anthropometric tables at both joints; through the
// realistic EXOwheel (data/plants/), the error rises and diagnose names the plant's damping; with the
// human side, the subject's own passive moment (drawn per subject) raises it further.
#include "tests/temp_dir.h"
#include "runner/table5_protocol.h"
#include "diagnosis/diagnose.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "model/regressors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace exotwin {
namespace {

// Bounds of the recovery from closed-loop data (real controller, 19-bit encoder, torque-sensor
// noise, 20 Hz derivatives), 1 trial x 20 s per step. See kJxPct / kYAbs below.
constexpr double kJxPct = 2.0;  // %, J and X
constexpr double kYAbs = 0.01;  // kg m, Y

void ExpectRecovered(const LumpedParams& id, const LumpedParams& truth, const std::string& what) {
  const double jx[4][2] = {{id.J1, truth.J1}, {id.J2, truth.J2}, {id.X1, truth.X1}, {id.X2, truth.X2}};
  const char* names[4] = {"J1", "J2", "X1", "X2"};
  for (int k = 0; k < 4; ++k)
    EXPECT_LE(100.0 * std::abs(jx[k][0] - jx[k][1]) / std::abs(jx[k][1]), kJxPct)
        << what << "." << names[k] << ": identified " << jx[k][0] << ", truth " << jx[k][1];
  EXPECT_LE(std::abs(id.Y1 - truth.Y1), kYAbs) << what << ".Y1: identified " << id.Y1 << ", truth " << truth.Y1;
  EXPECT_LE(std::abs(id.Y2 - truth.Y2), kYAbs) << what << ".Y2: identified " << id.Y2 << ", truth " << truth.Y2;
}

Effect Fx(const std::string& name, const std::string& joint, double value) {
  Effect e;
  e.name = name, e.joint = joint, e.value = value;
  return e;
}

// The knee cuff's compliance (rad/N m) a subject.yaml's identification block gives (identify
// --knee-cuff); -1 with a test failure when it gives none.
double KneeCuffCompliance(const std::string& subject_yaml) {
  std::ifstream f(subject_yaml);
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("  knee_cuff_compliance: ", 0) == 0) return std::stod(line.substr(24));
  ADD_FAILURE() << subject_yaml << ": no knee_cuff_compliance";
  return -1.0;
}

void ExpectPattern(const Table5JointRmse& r, const std::string& what) {
  for (double v : {r.identified, r.deleva, r.dempster}) {
    EXPECT_TRUE(std::isfinite(v)) << what;
    EXPECT_GT(v, 0.0) << what;
  }
  EXPECT_LT(r.identified, r.deleva) << what << ": identified vs De Leva";
  EXPECT_LT(r.identified, r.dempster) << what << ": identified vs Dempster";
}

TEST(Table5Protocol, TwoSubjectsShortTrialsRecoverTruthAndBeatAnthropometry) {
  Table5Options opt;
  opt.trials = 1;
  opt.trial_duration = 20.0;
  opt.strides = 4;
  opt.keep_logs = false;
  const testing::ScopedTempDir tmp("table5");
  opt.out_dir = tmp.path();
  for (const std::string subject : {"S1", "S7"}) {
    const Table5SubjectRun run = RunTable5Subject(subject, opt);
    const Table5Entry& e = run.entry;
    EXPECT_TRUE(run.failed_checks.empty()) << subject << ": " << (run.failed_checks.empty() ? "" : run.failed_checks[0]);
    ASSERT_TRUE(e.identified.human.has_value());
    ASSERT_TRUE(e.truth.human.has_value());
    ExpectRecovered(e.identified.exo, e.truth.exo, subject + " exo");
    ExpectRecovered(*e.identified.human, *e.truth.human, subject + " human");
    ExpectPattern(e.hip, subject + " hip");
    ExpectPattern(e.knee, subject + " knee");
    EXPECT_GT(e.gait_samples, 7000);
  }
}

// The run passed its checks, its identified RMS error lies in (lo, hi) per joint (N m) and below both
// anthropometric tables.
void ExpectIdentifiedIn(const Table5SubjectRun& run, std::pair<double, double> hip, std::pair<double, double> knee,
                        const std::string& what) {
  EXPECT_TRUE(run.failed_checks.empty()) << (run.failed_checks.empty() ? "" : run.failed_checks[0]);
  const Table5Entry& e = run.entry;
  EXPECT_GT(e.hip.identified, hip.first) << what;
  EXPECT_LT(e.hip.identified, hip.second) << what;
  EXPECT_GT(e.knee.identified, knee.first) << what;
  EXPECT_LT(e.knee.identified, knee.second) << what;
  ExpectPattern(e.hip, what + " hip");
  ExpectPattern(e.knee, what + " knee");
}

// S1 with short trials (1 x 20 s per step, 4 strides) through the realistic EXOwheel's sensor
// (data/plants/exowheel_realistic.yaml) and the worn file `worn` of data/plants/, diagnosed.
Table5Options RealisticS1Options(const std::string& worn, const std::string& out_dir) {
  Table5Options opt;
  opt.trials = 1;
  opt.trial_duration = 20.0;
  opt.strides = 4;
  opt.keep_logs = false;
  opt.plant_file = std::string(EXOTWIN_SOURCE_DIR) + "/data/plants/exowheel_realistic.yaml";
  opt.plant_worn_file = std::string(EXOTWIN_SOURCE_DIR) + "/data/plants/" + worn;
  opt.diagnose = true;
  opt.out_dir = out_dir;
  return opt;
}

// The realistic EXOwheel (data/plants/exowheel_realistic.yaml + relaxed_leg.yaml: sensor offset and gain,
// the relaxed leg's damping 0.2 / 0.1 N m s/rad) on S1 with short trials. Band of the identified RMS
// error: measured 0.29 / 0.16 N m (hip / knee) here, against 0.05 / 0.03 for the rigid twin; the band
// is that +-30 %. diagnose on the gait record must name the leg's damping at both joints within 25 % of
// the plant's (measured +9 % / -1 %) and halve the held-out error at both joints.
TEST(Table5Protocol, RealisticPlantRaisesTheErrorAndDiagnoseNamesItsDamping) {
  const testing::ScopedTempDir tmp("table5_realistic");
  const Table5Options opt = RealisticS1Options("relaxed_leg.yaml", tmp.path());
  const Table5SubjectRun run = RunTable5Subject("S1", opt);
  ExpectIdentifiedIn(run, {0.20, 0.38}, {0.11, 0.21}, "realistic");

  ASSERT_EQ(run.diagnoses.size(), 2u);
  const Table5Diagnosis& gait = run.diagnoses[0];
  ASSERT_EQ(gait.records, "gait");
  ASSERT_TRUE(gait.done) << gait.error;
  const double set[2] = {0.2, 0.1};  // relaxed_leg.yaml
  for (int j = 0; j < 2; ++j) {
    const char* joint = j ? "knee" : "hip";
    const Effect* named = nullptr;
    for (const Effect& fx : gait.named)
      if (fx.name == "viscous_friction" && fx.joint == joint) named = &fx;
    ASSERT_NE(named, nullptr) << joint << ": viscous_friction not named";
    EXPECT_NEAR(named->value, set[j], 0.25 * set[j]) << joint;
    EXPECT_LE(gait.rmse_after[j], 0.5 * gait.rmse_before[j]) << joint;
  }
  const std::string md = Table5DiagnosisMarkdown(opt, {run});
  EXPECT_NE(md.find("| viscous_friction (knee) | 0.1 | 1 |"), std::string::npos) << md;
}

// SubjectEffects: a passive_moment with a cv is drawn per subject, log-normal of mean 1 + value and
// that coefficient of variation (checked on 4000 names against the closed-form moments, tolerances
// 4 standard errors: mean 0.3 / sqrt(4000) -> 0.02, sd ~0.3 / sqrt(2 x 4000) x ~1.2 -> 0.02), the same
// bits for the same seed and name, the cv field dropped, effects without cv untouched.
TEST(Table5Protocol, SubjectEffectsDrawsTheCvPerSubject) {
  Effect pm = Fx("passive_moment", "knee", 0.0);
  pm.fields["cv"] = 0.3;
  const std::vector<Effect> fx = {Fx("viscous_friction", "knee", 0.1), pm};
  double sum = 0, sum2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const std::vector<Effect> d = SubjectEffects(fx, "X" + std::to_string(i), 1);
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d[0].value, 0.1);
    EXPECT_EQ(d[1].fields.count("cv"), 0u);
    const double f = 1 + d[1].value;
    ASSERT_GT(f, 0.0);
    sum += f, sum2 += f * f;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 1.0, 0.02);
  EXPECT_NEAR(sd, 0.3, 0.02);
  EXPECT_EQ(SubjectEffects(fx, "S3", 7)[1].value, SubjectEffects(fx, "S3", 7)[1].value);
  EXPECT_NE(SubjectEffects(fx, "S3", 7)[1].value, SubjectEffects(fx, "S3", 8)[1].value);
  EXPECT_NE(SubjectEffects(fx, "S3", 7)[1].value, SubjectEffects(fx, "S4", 7)[1].value);
}

// The human side (data/plants/human_side.yaml: the relaxed leg's damping, a knee strap of 1100 N m/rad,
// the subject's passive moment drawn with cv 0.3; S1, seed 1: hip -0.114, knee +0.004) on top of the
// realistic EXOwheel's sensor, S1 with short trials. The identified error rises from 0.29 / 0.16 N m
// (relaxed_leg.yaml, the test above) to 1.10 / 0.38 measured here; the band is that +-30 %, still below
// De Leva and Dempster. diagnose on the gait record names the hip's passive moment with the drawn
// sign but smaller (measured -0.065 against -0.114: steps 3-4's identification absorbed part of it in
// the gravity and inertia columns), so the band is 0.3-1.2 x the drawn factor; the extended twin cuts
// the hip's held-out error by at least 40 % (measured 50 %). S1/truth.yaml holds the twin the records
// came from.
TEST(Table5Protocol, HumanSideRaisesTheErrorAndDiagnoseNamesThePassiveMoment) {
  const testing::ScopedTempDir tmp("table5_human_side");
  const Table5SubjectRun run = RunTable5Subject("S1", RealisticS1Options("human_side.yaml", tmp.path()));
  ExpectIdentifiedIn(run, {0.77, 1.43}, {0.27, 0.50}, "human side");
  double drawn = 0;
  for (const Effect& fx : run.plant_worn)
    if (fx.name == "passive_moment" && fx.joint == "hip") drawn = fx.value;
  ASSERT_EQ(run.diagnoses.size(), 2u);
  const Table5Diagnosis& gait = run.diagnoses[0];
  ASSERT_TRUE(gait.done) << gait.error;
  const Effect* named = nullptr;
  for (const Effect& fx : gait.named)
    if (fx.name == "passive_moment" && fx.joint == "hip") named = &fx;
  ASSERT_NE(named, nullptr) << "passive_moment (hip) not named";
  EXPECT_NEAR(drawn, -0.114, 0.001) << "the draw of S1, seed 1 (SubjectEffects) changed";
  EXPECT_GT(named->value / drawn, 0.3) << named->value;
  EXPECT_LT(named->value / drawn, 1.2) << named->value;
  EXPECT_LE(gait.rmse_after[0], 0.6 * gait.rmse_before[0]);
  const std::string md = Table5DiagnosisMarkdown(RealisticS1Options("human_side.yaml", tmp.path()), {run});
  EXPECT_NE(md.find("Drawn passive_moment (hip, seed 1): S1 -0.114."), std::string::npos) << md;
  EXPECT_NE(md.find("| passive_moment (hip) | drawn per subject | 1 |"), std::string::npos) << md;

  // S1/truth.yaml: the twin the worn records came from. Its parameters are examples/S1.yaml's (the
  // preset written by hand), its effects the worn plant's in order (exowheel_realistic.yaml's sensor,
  // then human_side.yaml's), the cv draws resolved: the hip's passive moment is the draw above.
  const LegParams truth = ReadModelFile(tmp.path() + "/S1/truth.yaml");
  const LegParams s1 = ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml");
  ASSERT_TRUE(truth.human.has_value());
  EXPECT_EQ(truth.L1, s1.L1);
  EXPECT_EQ(truth.passive, s1.passive);
  for (const auto& [got, want] : {std::pair{truth.exo, s1.exo}, std::pair{*truth.human, *s1.human}}) {
    const double g[6] = {got.J1, got.J2, got.X1, got.X2, got.Y1, got.Y2};
    const double w[6] = {want.J1, want.J2, want.X1, want.X2, want.Y1, want.Y2};
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(g[k], w[k], 1e-9) << "J1, J2, X1, X2, Y1, Y2 [" << k << "]";
  }
  ASSERT_EQ(truth.effects.size(), 9u);  // 4 of the sensor, 5 of the human side
  ASSERT_EQ(truth.effects.size(), run.plant_worn.size());
  for (size_t k = 0; k < truth.effects.size(); ++k) {
    EXPECT_EQ(truth.effects[k].name, run.plant_worn[k].name) << k;
    EXPECT_EQ(truth.effects[k].joint, run.plant_worn[k].joint) << k;
    EXPECT_NEAR(truth.effects[k].value, run.plant_worn[k].value, 1e-9) << k;
    EXPECT_EQ(truth.effects[k].fields.count("cv"), 0u) << k;
  }
  EXPECT_EQ(truth.effects[6].name, "series_compliance");
  EXPECT_EQ(truth.effects[6].value, 1100.0);
  EXPECT_NEAR(truth.effects[7].value, drawn, 1e-9);
}

// The human side's strap in the gait (issue 41). S1's relaxed gait through the human side (the 10
// strides of `table5`), diagnosed by the motion fit with S1/truth.yaml less its strap, names the strap
// alone, within 10 % of human_side.yaml's 1100 N m/rad (measured 1134; on S2-S10 1116-1154). With the
// model identified by the paper's rows the strap lost to the identification's knee (X2 -4.6 % with the
// strap alone in the plant): identified with the knee cuff and the subject's passive moment, the model
// names it too.
TEST(Table5Protocol, TheHumanSidesStrapIsNamedInTheGaitWithTheTrueAndTheIdentifiedTwin) {
  const testing::ScopedTempDir tmp("table5_strap");
  Table5Options opt = RealisticS1Options("human_side.yaml", tmp.path());
  opt.strides = 10;
  opt.keep_logs = true;
  opt.diagnose = false;
  opt.knee_cuff = opt.subject_passive = true;
  RunTable5Subject("S1", opt);
  LegParams truth = ReadModelFile(tmp.path() + "/S1/truth.yaml");
  const size_t before = truth.effects.size();
  truth.effects.erase(std::remove_if(truth.effects.begin(), truth.effects.end(),
                                     [](const Effect& e) { return e.name == "series_compliance"; }),
                      truth.effects.end());
  ASSERT_EQ(truth.effects.size() + 1, before);
  const MeasuredData gait = ReadMeasuredCsv(tmp.path() + "/S1/gait/measured.csv");
  DiagnoseOptions dopt;
  dopt.fit = DiagnoseFit::kMotion;
  const Diagnosis d = Diagnose(truth, {&gait}, dopt);
  std::string named;
  for (const DiagnosedEffect& e : d.effects) named += e.effect.name + " (" + e.effect.joint + ") ";
  ASSERT_EQ(d.effects.size(), 1u) << named;
  EXPECT_EQ(d.effects[0].effect.name, "series_compliance");
  EXPECT_EQ(d.effects[0].effect.joint, "knee");
  EXPECT_NEAR(d.effects[0].effect.value, 1100.0, 110.0);

  // Issue 41's Table 5 target on S1: the model identified with the knee cuff and the subject's passive
  // moment (subject.yaml) names the strap from the same gait within 25 % (measured +5 %; with the
  // paper's rows the strap was not named, with the cuff alone at 1151 on full trials).
  const LegParams identified = ReadModelFile(tmp.path() + "/S1/subject.yaml");
  const Diagnosis di = Diagnose(identified, {&gait}, dopt);
  const DiagnosedEffect* strap = nullptr;
  for (const DiagnosedEffect& e : di.effects)
    if (e.effect.name == "series_compliance" && e.effect.joint == "knee") strap = &e;
  ASSERT_NE(strap, nullptr) << "identified model: the strap not named";
  EXPECT_NEAR(strap->effect.value, 1100.0, 275.0);
}

// The knee cuff fit (Table5Options::knee_cuff, identification.h KneeCuff) on S1 with short trials
// (1 x 20 s per step) and a 1100 N m/rad strap alone on the worn leg. A rigid cuff (HJ15 as
// published) evaluates the human's knee row at the exoskeleton's angle: X2 measured -3.6 % here. The
// fit recovers the strap (measured 1165 N m/rad, +5.9 %; bound 10 %) and the knee segment (X2 -0.05 %;
// bound 1 %, the rigid run must exceed 2.5 %). Without a strap it keeps the cuff rigid: the same
// parameters as the published method, bit for bit.
TEST(Table5Protocol, TheKneeCuffFitCarriesTheStrapThroughStepsThreeAndFour) {
  const testing::ScopedTempDir tmp("table5_knee_cuff");
  const std::string strap = tmp.path() + "/strap.yaml";
  {
    std::ofstream f(strap);
    f << "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\npassive: none\n"
         "effects:\n  - {name: series_compliance, joint: knee, value: 1100, unit: \"N m/rad\"}\n";
  }
  auto run = [&](bool with_strap, bool knee_cuff, const std::string& name) {
    Table5Options opt;
    opt.trials = 1;
    opt.trial_duration = 20.0;
    opt.strides = 2;
    opt.keep_logs = false;
    if (with_strap) opt.plant_worn_file = strap;
    opt.knee_cuff = knee_cuff;
    opt.out_dir = tmp.path() + "/" + name;
    const Table5SubjectRun r = RunTable5Subject("S1", opt);
    EXPECT_TRUE(r.failed_checks.empty()) << name;
    return r.entry;
  };
  auto cuff_compliance = [&](const std::string& name) {
    return KneeCuffCompliance(tmp.path() + "/" + name + "/S1/subject.yaml");
  };
  const Table5Entry rigid = run(true, false, "rigid"), cuff = run(true, true, "cuff");
  const LumpedParams& truth = *cuff.truth.human;
  const double c = cuff_compliance("cuff");
  EXPECT_NEAR(1.0 / c, 1100.0, 110.0);
  EXPECT_LE(std::abs(cuff.identified.human->X2 / truth.X2 - 1), 0.01) << cuff.identified.human->X2;
  EXPECT_LE(std::abs(cuff.identified.human->J2 / truth.J2 - 1), 0.01) << cuff.identified.human->J2;
  EXPECT_LE(std::abs(cuff.identified.human->Y1 - truth.Y1), kYAbs) << cuff.identified.human->Y1;
  EXPECT_GT(std::abs(rigid.identified.human->X2 / truth.X2 - 1), 0.025) << rigid.identified.human->X2;

  const Table5Entry plain = run(false, false, "plain"), plain_cuff = run(false, true, "plain_cuff");
  EXPECT_EQ(cuff_compliance("plain_cuff"), 0.0);
  const Vector6 a = ToVector(*plain.identified.human), b = ToVector(*plain_cuff.identified.human);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(a[k], b[k]) << k;
}

// The human side (realistic EXOwheel + human_side.yaml: a 1100 N m/rad strap, the relaxed leg's
// damping 0.2 / 0.1 N m s/rad, the subject's passive moment drawn off Riener & Edrich's curve) on S1
// with short trials (1 x 20 s per step), identified with the knee cuff and the subject's passive
// moment (Table5Options::knee_cuff, subject_passive). Measured here: the drawn factors within 0.011,
// the damping +1.8 % / +3.8 %, J and X within 1.35 %, Y within 0.024 kg m, the strap 1348 N m/rad
// (+23 %). Bounds: factors 0.03, damping 10 %, J and X 2 %, Y 0.04 kg m, strap 35 %. The paper's rows on
// the same records miss X2 by more than 4 % (measured -5.9 % with 5 x 40 s trials).
TEST(Table5Protocol, TheHumanSidesPassiveMomentDampingAndCuffAreIdentified) {
  const testing::ScopedTempDir tmp("table5_subject_passive");
  Table5Options opt = RealisticS1Options("human_side.yaml", tmp.path() + "/fit");
  opt.strides = 2;
  opt.diagnose = false;
  opt.keep_logs = true;
  opt.knee_cuff = true;
  opt.subject_passive = true;
  const Table5SubjectRun run = RunTable5Subject("S1", opt);
  const LumpedParams& id = *run.entry.identified.human;
  const LumpedParams& truth = *run.entry.truth.human;
  const double jx[4][2] = {{id.J1, truth.J1}, {id.J2, truth.J2}, {id.X1, truth.X1}, {id.X2, truth.X2}};
  for (int k = 0; k < 4; ++k) EXPECT_LE(std::abs(jx[k][0] / jx[k][1] - 1), 0.02) << k << ": " << jx[k][0];
  EXPECT_LE(std::abs(id.Y1 - truth.Y1), 0.04) << id.Y1;
  EXPECT_LE(std::abs(id.Y2 - truth.Y2), 0.04) << id.Y2;
  const LegParams written = ReadModelFile(tmp.path() + "/fit/S1/subject.yaml");
  for (const char* joint : {"hip", "knee"}) {
    const Effect *factor = nullptr, *damping = nullptr, *drawn = nullptr;
    for (const Effect& e : written.effects)
      if (e.joint == joint) (e.name == "passive_moment" ? factor : damping) = &e;
    for (const Effect& e : run.plant_worn)
      if (e.joint == joint && e.name == "passive_moment") drawn = &e;
    ASSERT_TRUE(factor && damping && drawn) << joint;
    EXPECT_EQ(damping->name, "viscous_friction");
    EXPECT_NEAR(factor->value, drawn->value, 0.03) << joint;
    EXPECT_NEAR(damping->value, joint == std::string("hip") ? 0.2 : 0.1,
                joint == std::string("hip") ? 0.02 : 0.01) << joint;
  }
  const double c = KneeCuffCompliance(tmp.path() + "/fit/S1/subject.yaml");
  ASSERT_GT(c, 0.0);
  EXPECT_NEAR(1.0 / c, 1100.0, 0.35 * 1100.0);

  opt.knee_cuff = opt.subject_passive = false;
  opt.out_dir = tmp.path() + "/paper";
  const Table5SubjectRun paper = RunTable5Subject("S1", opt);
  EXPECT_GT(std::abs(paper.entry.identified.human->X2 / truth.X2 - 1), 0.04) << paper.entry.identified.human->X2;
}

}  // namespace
}  // namespace exotwin
