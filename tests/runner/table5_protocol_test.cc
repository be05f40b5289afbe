// The Table 5 protocol end to end on 2 subjects with short trials (scenarios/table5_protocol.h):
// identification through the closed loop recovers the hidden truth, and the identified parameters
// predict the relaxed-gait torque better than both anthropometric tables at both joints; through the
// realistic EXOwheel (data/plants/), the error rises and diagnose names the plant's damping.
#include "tests/temp_dir.h"
#include "runner/table5_protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

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

// The realistic EXOwheel (data/plants/exowheel_realistic.yaml + relaxed_leg.yaml: sensor offset and gain,
// the relaxed leg's damping 0.2 / 0.1 N m s/rad) on S1 with short trials. Band of the identified RMS
// error: measured 0.29 / 0.16 N m (hip / knee) here, against 0.05 / 0.03 for the rigid twin; the band
// is that +-30 %. diagnose on the gait record must name the leg's damping at both joints within 25 % of
// the plant's (measured +9 % / -1 %) and halve the held-out error at both joints.
TEST(Table5Protocol, RealisticPlantRaisesTheErrorAndDiagnoseNamesItsDamping) {
  Table5Options opt;
  opt.trials = 1;
  opt.trial_duration = 20.0;
  opt.strides = 4;
  opt.keep_logs = false;
  opt.plant_file = std::string(EXOTWIN_SOURCE_DIR) + "/data/plants/exowheel_realistic.yaml";
  opt.plant_worn_file = std::string(EXOTWIN_SOURCE_DIR) + "/data/plants/relaxed_leg.yaml";
  opt.diagnose = true;
  const testing::ScopedTempDir tmp("table5_realistic");
  opt.out_dir = tmp.path();
  const Table5SubjectRun run = RunTable5Subject("S1", opt);
  EXPECT_TRUE(run.failed_checks.empty()) << (run.failed_checks.empty() ? "" : run.failed_checks[0]);
  const Table5Entry& e = run.entry;
  EXPECT_GT(e.hip.identified, 0.20);
  EXPECT_LT(e.hip.identified, 0.38);
  EXPECT_GT(e.knee.identified, 0.11);
  EXPECT_LT(e.knee.identified, 0.21);
  ExpectPattern(e.hip, "realistic hip");
  ExpectPattern(e.knee, "realistic knee");

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

}  // namespace
}  // namespace exotwin
