// The derivative cutoff chosen from the data (derivative_cutoff.h): on a clean record it keeps the
// motion (at least twice the generator's fastest harmonic, 1.5 Hz); on the same motion read through
// a coarse encoder it filters no less, and the torque predicted at its choice is closer to the clean
// record's than the paper's 20 Hz is (an independent reference: the fine encoder's kinematics, not
// the criterion the choice minimizes).
#include <gtest/gtest.h>

#include <cmath>

#include "diagnosis/derivative_cutoff.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "core/error.h"
#include "model/leg_dynamics.h"

namespace exotwin {
namespace {

LegParams S1() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml"); }

// RMS over both joints of the rigid twin's torque from `a`'s kinematics (derivatives at fa) against
// `b`'s (at fb), the difference low-passed at `post` Hz when post > 0; 1 s from each end.
double TorqueRmsDiff(const LegParams& p, const MeasuredData& a, double fa, const MeasuredData& b, double fb,
                     double post) {
  const Kinematics ka = DeriveKinematics(a, fa), kb = DeriveKinematics(b, fb);
  std::vector<double> d[2] = {std::vector<double>(ka.t.size()), std::vector<double>(ka.t.size())};
  for (size_t i = 0; i < ka.t.size(); ++i) {
    const Eigen::Vector2d ta = ActuatorTorque(p, {ka.q[0][i], ka.q[1][i]}, {ka.qd[0][i], ka.qd[1][i]},
                                              {ka.qdd[0][i], ka.qdd[1][i]});
    const Eigen::Vector2d tb = ActuatorTorque(p, {kb.q[0][i], kb.q[1][i]}, {kb.qd[0][i], kb.qd[1][i]},
                                              {kb.qdd[0][i], kb.qdd[1][i]});
    d[0][i] = ta[0] - tb[0], d[1][i] = ta[1] - tb[1];
  }
  double s = 0, n = 0;
  for (auto& x : d) {
    if (post > 0) x = LowPassOnTimeBase(a.t(), x, post, a.source);
    for (size_t i = 500; i + 500 < x.size(); ++i) s += x[i] * x[i], n += 1;
  }
  return std::sqrt(s / n);
}

// For both uses: kDerivatives (the torque from angles differentiated at the cutoff) and kParallel
// (differentiated at 4 fc, the torque low-passed at fc, as diagnose does).
TEST(DerivativeCutoff, CleanRecordKeepsTheMotionCoarseEncoderPredictsBetterThanTwentyHertz) {
  const LegParams p = S1();
  for (const CutoffUse use : {CutoffUse::kDerivatives, CutoffUse::kParallel}) {
  const bool parallel = use == CutoffUse::kParallel;
  GenerateOptions g;
  g.seed = 21, g.effects = 0, g.duration = 20, g.rate = 500;
  const MeasuredData fine = GenerateMeasured(p, g).data;
  const CutoffChoice cf = ChooseCutoff({&fine}, p.L1, p.g, use);
  EXPECT_GE(cf.hz, 2 * 1.5) << cf.why;  // GenerateMeasured: harmonics of 0.3-1.5 Hz
  // The same motion through a 12-bit encoder (4096 counts per turn), as on a low-cost rig.
  MeasuredData coarse = fine;
  const double count = 2 * M_PI / 4096;
  for (auto* q : {&coarse.column_at(kColQHip), &coarse.column_at(kColQKnee)})
    for (double& v : *q) v = count * std::round(v / count);
  const CutoffChoice cc = ChooseCutoff({&coarse}, p.L1, p.g, use);
  EXPECT_LE(cc.hz, cf.hz) << cc.why;
  EXPECT_LT(cc.hz, 20.0) << cc.why;
  ASSERT_EQ(cc.candidates_hz.size(), cc.score.size());
  const double at_choice = parallel ? TorqueRmsDiff(p, coarse, DerivativeCutoffHz(cc.hz, 500), fine, 20.0, cc.hz)
                                    : TorqueRmsDiff(p, coarse, cc.hz, fine, 20.0, 0);
  const double at_20 = parallel ? TorqueRmsDiff(p, coarse, DerivativeCutoffHz(20, 500), fine, 20.0, 20)
                                : TorqueRmsDiff(p, coarse, 20.0, fine, 20.0, 0);
  std::printf("%s: fine %g Hz; coarse %g Hz, torque error against the fine record %.4f N m (20 Hz: %.4f)\n",
              parallel ? "parallel" : "derivatives", cf.hz, cc.hz, at_choice, at_20);
  EXPECT_LT(at_choice, 0.8 * at_20);
  }
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
