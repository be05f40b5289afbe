// The derivative cutoff chosen from the data (derivative_cutoff.h): on a clean record it keeps the
// motion (at least twice the generator's fastest harmonic, 1.5 Hz); on the same motion read through
// a coarse encoder it filters no less, and the torque predicted at its choice is closer to the clean
// record's than the paper's 20 Hz is (an independent reference: the fine encoder's kinematics, not
// the criterion the choice minimizes).
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/derivative_cutoff.h"
#include "analysis/generate.h"
#include "analysis/model_file.h"
#include "model/input_error.h"
#include "model/leg_dynamics.h"

namespace exotwin {
namespace {

LegParams S1() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml"); }

// RMS over both joints of the rigid twin's torque from `a`'s kinematics at fa against `b`'s at fb,
// 1 s from each end (filter edges).
double TorqueRmsDiff(const LegParams& p, const MeasuredData& a, double fa, const MeasuredData& b, double fb) {
  const Kinematics ka = DeriveKinematics(a, fa), kb = DeriveKinematics(b, fb);
  double s = 0, n = 0;
  for (size_t i = 500; i + 500 < ka.t.size(); ++i) {
    const Eigen::Vector2d ta = ActuatorTorque(p, {ka.q[0][i], ka.q[1][i]}, {ka.qd[0][i], ka.qd[1][i]},
                                              {ka.qdd[0][i], ka.qdd[1][i]});
    const Eigen::Vector2d tb = ActuatorTorque(p, {kb.q[0][i], kb.q[1][i]}, {kb.qd[0][i], kb.qd[1][i]},
                                              {kb.qdd[0][i], kb.qdd[1][i]});
    s += (ta - tb).squaredNorm(), n += 2;
  }
  return std::sqrt(s / n);
}

TEST(DerivativeCutoff, CleanRecordKeepsTheMotionCoarseEncoderPredictsBetterThanTwentyHertz) {
  const LegParams p = S1();
  GenerateOptions g;
  g.seed = 21, g.effects = 0, g.duration = 20, g.rate = 500;
  const MeasuredData fine = GenerateMeasured(p, g).data;
  const CutoffChoice cf = ChooseCutoff({&fine}, p.L1, p.g);
  EXPECT_GE(cf.hz, 2 * 1.5) << cf.why;  // GenerateMeasured: harmonics of 0.3-1.5 Hz
  // The same motion through a 12-bit encoder (4096 counts per turn), as on a low-cost rig.
  MeasuredData coarse = fine;
  const double count = 2 * M_PI / 4096;
  for (auto* q : {&coarse.q_hip, &coarse.q_knee})
    for (double& v : *q) v = count * std::round(v / count);
  const CutoffChoice cc = ChooseCutoff({&coarse}, p.L1, p.g);
  EXPECT_LE(cc.hz, cf.hz) << cc.why;
  EXPECT_LT(cc.hz, 20.0) << cc.why;
  ASSERT_EQ(cc.candidates_hz.size(), cc.score.size());
  const double at_choice = TorqueRmsDiff(p, coarse, cc.hz, fine, 20.0);
  const double at_20 = TorqueRmsDiff(p, coarse, 20.0, fine, 20.0);
  std::printf("fine: %g Hz; coarse: %g Hz, torque error against the fine record %.4f N m (20 Hz: %.4f)\n",
              cf.hz, cc.hz, at_choice, at_20);
  EXPECT_LT(at_choice, 0.8 * at_20);
}

TEST(DerivativeCutoff, OptionValues) {
  EXPECT_EQ(ParseCutoffOption("auto", "--cutoff"), 0.0);
  EXPECT_EQ(ParseCutoffOption("7.5", "--cutoff"), 7.5);
  for (const char* bad : {"", "0", "-3", "fast", "5Hz", "nan", "inf"})
    EXPECT_THROW(ParseCutoffOption(bad, "--cutoff"), InputError) << bad;
  try {
    ParseCutoffOption("fast", "predict --cutoff");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("predict --cutoff"), std::string::npos);
  }
}

}  // namespace
}  // namespace exotwin
