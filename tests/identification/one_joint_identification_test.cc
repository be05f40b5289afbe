// identify's one-joint case (identification/one_joint_identification.h): least squares of HKS05
// eq. 4 on a record made from known values in closed form (recovered within 4 standard errors, the
// standard errors consistent with the noise), and the real pendulum's reference fit (../shared/data).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/rng.h"
#include "formats/column_map.h"
#include "identification/one_joint_identification.h"

namespace exotwin {
namespace {

// A one-joint record of tau_S = -(I qdd + R qd + C sgn(qd) + mgl sin q) + noise, q a sum of sines.
MeasuredData SwingRecord(double I, double mgl, double R, double C, double noise, uint64_t seed) {
  NormalRng<NormalBoxMuller<BoxMullerU1::kOneMinusUniform>> rng(seed);
  CsvTable t;
  t.names = {"t", "q_knee", "tau_knee", "qd_knee", "qdd_knee"};
  t.columns.assign(5, {});
  for (int i = 0; i < 6000; ++i) {
    const double s = 0.002 * i;
    const double q = 0.4 + 0.5 * std::sin(2.3 * s) + 0.25 * std::sin(5.1 * s + 1);
    const double qd = 0.5 * 2.3 * std::cos(2.3 * s) + 0.25 * 5.1 * std::cos(5.1 * s + 1);
    const double qdd = -0.5 * 2.3 * 2.3 * std::sin(2.3 * s) - 0.25 * 5.1 * 5.1 * std::sin(5.1 * s + 1);
    const double tau = I * qdd + R * qd + C * (qd > 0 ? 1 : qd < 0 ? -1 : 0) + mgl * std::sin(q);
    const double row[5] = {s, q, -tau + noise * rng.Normal(), qd, qdd};
    for (int c = 0; c < 5; ++c) t.columns[c].push_back(row[c]);
  }
  return MeasuredFromTable(std::move(t), "swing.csv");
}

TEST(OneJointIdentification, RecoversKnownValuesWithinTheirStandardErrors) {
  const double truth[4] = {0.53, 13.3, 0.8, 0.4};
  std::vector<MeasuredData> recs;
  recs.push_back(SwingRecord(truth[0], truth[1], truth[2], truth[3], 0.05, 7));
  ASSERT_TRUE(recs[0].one_joint);
  const OneJointEstimate e = IdentifyOneJoint(recs, 20, 0.1, true);
  ASSERT_EQ(e.value.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT(std::abs(e.value[k] - truth[k]), 4 * e.se[k]) << e.names[k];
    EXPECT_LT(e.se[k], 0.02 * truth[k]) << e.names[k];
  }
  EXPECT_NEAR(e.rmse, 0.05, 0.005);  // the residual is the noise
  // Without friction terms the model misses R and C: a larger residual.
  EXPECT_GT(IdentifyOneJoint(recs, 20, 0.1, false).rmse, 2 * e.rmse);
}

TEST(OneJointIdentification, TwoJointRecordsAndStillJointsAreRejected) {
  CsvTable t;
  t.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  t.columns.assign(5, std::vector<double>(300, 0.0));
  for (int i = 0; i < 300; ++i) t.columns[0][i] = 0.01 * i;
  std::vector<MeasuredData> two;
  two.push_back(MeasuredFromTable(t, "two.csv"));
  EXPECT_THROW(IdentifyOneJoint(two, 20, 0.1, false), InputError);
  CsvTable still;
  still.names = {"t", "q_knee", "tau_knee"};
  still.columns = {t.columns[0], std::vector<double>(300, 0.3), std::vector<double>(300, -1.0)};
  std::vector<MeasuredData> one;
  one.push_back(MeasuredFromTable(still, "still.csv"));
  EXPECT_THROW(IdentifyOneJoint(one, 20, 0.1, false), InputError);  // no swing: no rank
}

// The real pendulum's dynamic records: the README's reference fit (I 0.177 kg m^2, mgl 3.53 N m,
// Coulomb 0.15 N m) within 5 %, 5 % and 30 %.
TEST(OneJointIdentification, RealPendulumReachesTheReferenceFit) {
  const std::string dir = std::string(EXOTWIN_SOURCE_DIR) + "/../shared/data/real_rig/dfki_simple_pendulum/";
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " absent";
  const std::string map = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/simple_pendulum/dfki_simple_pendulum.map.yaml";
  std::vector<MeasuredData> recs;
  for (const char* f : {"pd_system_identification.csv", "ddp_swingup.csv"}) recs.push_back(ReadMeasured(dir + f, map));
  const OneJointEstimate e = IdentifyOneJoint(recs, 5, 0.1, true);
  for (size_t k = 0; k < e.names.size(); ++k)
    std::printf("%s = %.4g +- %.2g\n", e.names[k].c_str(), e.value[k], e.se[k]);
  EXPECT_NEAR(e.value[0], 0.177, 0.05 * 0.177);
  EXPECT_NEAR(e.value[1], 3.53, 0.05 * 3.53);
  EXPECT_NEAR(e.value[3], 0.15, 0.3 * 0.15);
}

}  // namespace
}  // namespace exotwin
