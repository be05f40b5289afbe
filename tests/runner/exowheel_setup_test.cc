// runner/exowheel_setup.h BuildTrajectory with `trajectory: file`: Winter's stride written by the test
// as an OpenSim motion file (every header variant) drives the same reference as the gait scenario's
// Fourier fit; bad motion files throw InputError naming the file and the line.
#include "runner/exowheel_setup.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/units.h"
#include "runner/scenario.h"
#include "tests/motion_file.h"
#include "tests/temp_dir.h"
#include "tests/winter_stride.h"

namespace exotwin {
namespace {

using testing::MotText;
using testing::MotVariant;

Scenario FileScenario(const std::string& dir, const std::string& extra = "") {
  return ParseScenarioYaml("name: x\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: file, "
                           "path: walk.mot, duration: 10, ramp: 2" + extra + "}\n",
                           dir + "/x.yaml");
}

// Largest differences (q rad, qd rad/s, qdd rad/s^2) between two references over [t0, t1].
void MaxDiff(const controller::LegTrajectory& a, const controller::LegTrajectory& b, double t0, double t1,
             double out[3]) {
  out[0] = out[1] = out[2] = 0;
  for (double t = t0; t <= t1; t += 0.0007) {
    controller::JointSetpoint ah, ak, bh, bk;
    a.Sample(t, &ah, &ak);
    b.Sample(t, &bh, &bk);
    out[0] = std::max({out[0], std::abs(ah.q - bh.q), std::abs(ak.q - bk.q)});
    out[1] = std::max({out[1], std::abs(ah.qd - bh.qd), std::abs(ak.qd - bk.qd)});
    out[2] = std::max({out[2], std::abs(ah.qdd - bh.qdd), std::abs(ak.qdd - bk.qdd)});
  }
}

TEST(RecordedTrajectory, WinterStrideFromAMotionFileLoopsAsTheGaitScenario) {
  const testing::ScopedTempDir tmp("rec_traj");
  const testing::SampledStride w = testing::WinterStride(100.0, 0.75);  // a file need not start at 0
  Scenario gait = FileScenario(tmp.path());
  gait.protocol.trajectory = TrajectoryKind::kGait;
  const auto ref = BuildTrajectory(gait, 0);
  using H = MotVariant::Header;
  for (H h : {H::kVersion1, H::kToolLines, H::kSimm}) {
    MotVariant v;
    v.header = h;
    v.sep = h == H::kVersion1 ? '\t' : ' ';
    v.trailing_sep = h == H::kSimm;
    std::ofstream(tmp.path() + "/walk.mot") << MotText(w.t, w.hip, w.knee, v);
    const auto rec = BuildTrajectory(FileScenario(tmp.path()), 0);
    double d[3];
    MaxDiff(*rec, *ref, 0.0, 10.0, d);  // the ramp, then four strides: the loop seam every 2 s
    EXPECT_LT(d[0] * kDegPerRad, 0.02) << static_cast<int>(h);  // deg
    EXPECT_LT(d[1] * kDegPerRad, 1.0) << static_cast<int>(h);   // deg/s, of 250 deg/s peak
    EXPECT_LT(d[2] * kDegPerRad, 60.0) << static_cast<int>(h);  // deg/s^2, of 3000 deg/s^2 peak
  }
}

TEST(RecordedTrajectory, NonUniformSamplesAreResampledAndHoldStops) {
  const testing::ScopedTempDir tmp("rec_traj2");
  testing::SampledStride w = testing::WinterStride(100.0);
  for (size_t i = 1; i + 1 < w.t.size(); i += 2) w.t[i] += 0.002;  // jittered clock
  MotVariant v;
  v.in_degrees = false;
  std::ofstream(tmp.path() + "/walk.mot") << MotText(w.t, w.hip, w.knee, v);
  const auto rec = BuildTrajectory(FileScenario(tmp.path(), ", extend: hold, cutoff: 6"), 0);
  controller::JointSetpoint h, k;
  rec->Sample(9.0, &h, &k);
  EXPECT_EQ(h.qd, 0.0);
  EXPECT_NEAR(k.q, w.knee.back(), 1.0 * kRadPerDeg);
}

TEST(RecordedTrajectory, BadMotionFilesNameTheFileAndLine) {
  const testing::ScopedTempDir tmp("rec_traj3");
  const testing::SampledStride w = testing::WinterStride(50.0);
  const std::string path = tmp.path() + "/walk.mot";
  auto expect = [&](const std::string& text, const std::string& piece, const std::string& extra = "") {
    std::ofstream(path) << text;
    try {
      BuildTrajectory(FileScenario(tmp.path(), extra), 0);
      ADD_FAILURE() << "no error for " << piece;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(piece), std::string::npos) << e.what();
    }
  };
  MotVariant v;
  v.state_unit = false;
  expect(MotText(w.t, w.hip, w.knee, v), "inDegrees");
  expect(MotText(w.t, w.hip, w.knee, MotVariant()), "Nyquist", ", cutoff: 30");
  std::remove(path.c_str());
  try {
    BuildTrajectory(FileScenario(tmp.path()), 0);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("walk.mot"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace exotwin
