// Videos: the file decodes, frame count = duration x fps, consecutive frames differ while the leg
// moves and are (nearly) equal when it holds still, the leg is where the kinematics say in decoded
// frames, overlays are drawn, and the file appears atomically. Videos are 2 s long, in a temp dir.
#include "render/video_renderer.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>

#include <opencv2/videoio.hpp>

#include "core/error.h"
#include "render/scene_renderer.h"
#include "sim/plant.h"
#include "tests/render/render_test_util.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;
using testing::FractionNear;
using testing::IsExo;
using testing::IsSkin;
using testing::MeanAbsDiff;
using testing::TestPose;

std::vector<cv::Mat> Decode(const std::string& path, double* fps = nullptr) {
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  EXPECT_TRUE(cap.isOpened()) << path;
  if (fps) *fps = cap.get(cv::CAP_PROP_FPS);
  std::vector<cv::Mat> frames;
  cv::Mat f;
  while (cap.read(f)) frames.push_back(f.clone());
  return frames;
}

// A region of the scene that no overlay covers (between the angle panel and the charts).
const cv::Rect kSceneRoi(320, 130, 500, 380);

class VideoRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    plant_ = std::make_unique<Plant>(ShippedModelPath("leg_exowheel.xml"));
  }

  // Simulated feed at 1 kHz over [0, duration): the test motion until t_move, then still; the
  // leg pose is written into the plant's mjData as the physics would.
  void Feed(VideoRenderer& r, double duration, double t_move, double rate_hz = 1000.0,
            const std::string& event_at_1s = "") {
    mjData* d = plant_->data();
    const int hip = plant_->model()->jnt_qposadr[mj_name2id(plant_->model(), mjOBJ_JOINT, "hip")];
    const int knee = plant_->model()->jnt_qposadr[mj_name2id(plant_->model(), mjOBJ_JOINT, "knee")];
    const long n = std::lround(duration * rate_hz);
    for (long i = 0; i < n; ++i) {
      OverlaySample s;
      s.t = i / rate_hz;
      TestPose(s.t, t_move, &s.q_hip, &s.q_knee);
      d->qpos[hip] = s.q_hip;
      d->qpos[knee] = s.q_knee;
      s.tau_meas[0] = -20 + 5 * std::sin(3 * s.t), s.tau_meas[1] = 4 * std::cos(2 * s.t);
      s.tau_est[0] = s.tau_meas[0] + 1.0, s.tau_est[1] = s.tau_meas[1] - 0.5;
      s.emg = {0.1 + 0.05 * std::sin(s.t), 0.2};
      if (!event_at_1s.empty() && i == long(rate_hz)) s.event = event_at_1s;
      r.AddSample(d, s);
    }
  }

  std::unique_ptr<Plant> plant_;
  const testing::ScopedTempDir tmp_{"render_video"};
  const std::string dir_ = tmp_.path();
};

TEST_F(VideoRendererTest, DecodesWithDurationTimesFpsFramesAndH264) {
  const std::string path = dir_ + "/leg.mp4";
  RenderOptions opt;
  opt.emg_names = {"VM", "RF"};
  VideoRenderer r(plant_->model(), path, opt);
  Feed(r, 2.0, 2.0);
  r.Finish();
  EXPECT_EQ(r.frames(), 60);
  EXPECT_EQ(r.stats().frames, 60);
  ASSERT_TRUE(fs::exists(path));
  double fps = 0;
  const auto frames = Decode(path, &fps);
  EXPECT_EQ(frames.size(), 60u);
  EXPECT_NEAR(fps, 30.0, 1e-6);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames[0].cols, 1280);
  EXPECT_EQ(frames[0].rows, 720);
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  const int fourcc = int(cap.get(cv::CAP_PROP_FOURCC));
  const std::string cc{char(fourcc & 255), char((fourcc >> 8) & 255), char((fourcc >> 16) & 255),
                       char((fourcc >> 24) & 255)};
  EXPECT_EQ(cc, r.codec());
  EXPECT_EQ(r.codec(), "avc1") << "H.264 unavailable: the writer fell back to " << r.codec();
}

TEST_F(VideoRendererTest, FramesDifferWhileMovingAndNotWhenStill) {
  const std::string path = dir_ + "/still.mp4";
  VideoRenderer r(plant_->model(), path);
  Feed(r, 2.0, 1.0);  // moves during [0, 1) s, still during [1, 2) s
  r.Finish();
  const auto f = Decode(path);
  ASSERT_EQ(f.size(), 60u);
  for (int k = 1; k < 29; ++k)
    EXPECT_GT(MeanAbsDiff(f[k], f[k - 1], kSceneRoi), 0.5) << "frames " << k - 1 << "," << k << " (moving)";
  for (int k = 33; k < 60; ++k)
    EXPECT_LT(MeanAbsDiff(f[k], f[k - 1], kSceneRoi), 0.3) << "frames " << k - 1 << "," << k << " (still)";
}

TEST_F(VideoRendererTest, LegInDecodedFramesIsWhereTheKinematicsSay) {
  const std::string path = dir_ + "/kin.mp4";
  VideoRenderer r(plant_->model(), path);
  Feed(r, 2.0, 2.0);
  const CameraView view = r.scene().view();
  r.Finish();
  const auto frames = Decode(path);
  ASSERT_EQ(frames.size(), 60u);
  const mjModel* m = plant_->model();
  mjData* d = mj_makeData(m);
  const int shank = mj_name2id(m, mjOBJ_BODY, "human_shank");
  const int bar = mj_name2id(m, mjOBJ_GEOM, "exo_shank_bar");
  for (int k : {0, 13, 27, 44}) {
    // Frame k shows the latest 1 kHz sample at or before k / 30 s.
    const double t = std::floor(k * 1000.0 / 30.0 + 1e-6) / 1000.0;
    TestPose(t, 2.0, &d->qpos[m->jnt_qposadr[0]], &d->qpos[m->jnt_qposadr[1]]);
    mj_kinematics(m, d);
    // Foot: 0.12 m forward of the shank axis at the foot (shank frame z = -0.5 m), clear of the bar.
    double toe[3], toe_local[3] = {0.12, 0, -0.5};
    mju_mulMatVec(toe, d->xmat + 9 * shank, toe_local, 3, 3);
    for (int i = 0; i < 3; ++i) toe[i] += d->xpos[3 * shank + i];
    const PixelPoint pf = ProjectToPixel(view, toe);
    EXPECT_GT(FractionNear(frames[k], pf.u, pf.v, 2, IsSkin), 0.8) << "frame " << k << " foot";
    double face[3], local[3] = {0, 0.03, 0};
    mju_mulMatVec(face, d->geom_xmat + 9 * bar, local, 3, 3);
    for (int i = 0; i < 3; ++i) face[i] += d->geom_xpos[3 * bar + i];
    const PixelPoint pb = ProjectToPixel(view, face);
    EXPECT_GT(FractionNear(frames[k], pb.u, pb.v, 2, IsExo), 0.8) << "frame " << k << " shank bar";
  }
  mj_deleteData(d);
}

TEST_F(VideoRendererTest, OverlaysAreDrawn) {
  const std::string with = dir_ + "/with.mp4", without = dir_ + "/without.mp4";
  {
    VideoRenderer r(plant_->model(), with);
    Feed(r, 2.0, 0.0, 1000.0, "CAN bus-off on node 3");  // leg still: only overlays change
    r.Finish();
  }
  {
    RenderOptions opt;
    opt.overlays = false;
    VideoRenderer r(plant_->model(), without, opt);
    Feed(r, 2.0, 0.0);
    r.Finish();
  }
  const auto a = Decode(with), b = Decode(without);
  ASSERT_EQ(a.size(), 60u);
  ASSERT_EQ(b.size(), 60u);
  const cv::Rect text(12, 12, 300, 110), charts(860, 12, 408, 450), events(12, 520, 560, 188);
  // Time text changes from frame to frame although nothing moves.
  EXPECT_GT(MeanAbsDiff(a[10], a[40], text), 1.0);
  EXPECT_LT(MeanAbsDiff(b[10], b[40], text), 0.3);
  // Overlays differ from the bare scene in the text, chart and (after the fault at 1 s) event areas.
  EXPECT_GT(MeanAbsDiff(a[40], b[40], text), 5.0);
  EXPECT_GT(MeanAbsDiff(a[40], b[40], charts), 5.0);
  EXPECT_LT(MeanAbsDiff(a[20], b[20], events), 1.0) << "no event panel before the fault";
  EXPECT_GT(MeanAbsDiff(a[40], b[40], events), 3.0) << "event panel after the fault";
}

TEST_F(VideoRendererTest, SparseSamplesStillGiveDurationTimesFps) {
  const std::string path = dir_ + "/sparse.mp4";
  VideoRenderer r(plant_->model(), path);
  Feed(r, 2.0, 2.0, 10.0);  // 10 Hz samples at 0, 0.1, ..., 1.9 s: frames are repeated
  r.Finish(2.0);             // the record ends one sample period after the last sample
  const auto f = Decode(path);
  ASSERT_EQ(f.size(), 60u);
  // Sample and hold: frames at 0, 1/30 and 2/30 s show the state at 0 s; the frame at 0.1 s the
  // state at 0.1 s (never a future state).
  EXPECT_LT(MeanAbsDiff(f[1], f[0], kSceneRoi), 0.3);
  EXPECT_LT(MeanAbsDiff(f[2], f[0], kSceneRoi), 0.3);
  EXPECT_GT(MeanAbsDiff(f[3], f[2], kSceneRoi), 0.5);
}

TEST_F(VideoRendererTest, OtherSizeAndFps) {
  const std::string path = dir_ + "/small.mp4";
  RenderOptions opt;
  opt.width = 640, opt.height = 360, opt.fps = 25;
  VideoRenderer r(plant_->model(), path, opt);
  Feed(r, 2.0, 2.0);
  r.Finish();
  const auto f = Decode(path);
  ASSERT_EQ(f.size(), 50u);
  EXPECT_EQ(f[0].cols, 640);
  EXPECT_EQ(f[0].rows, 360);
}

TEST_F(VideoRendererTest, WritesAtomically) {
  const std::string path = dir_ + "/atomic.mp4";
  {
    VideoRenderer r(plant_->model(), path);
    Feed(r, 0.5, 0.5);
    EXPECT_FALSE(fs::exists(path));
    EXPECT_TRUE(fs::exists(dir_ + "/atomic.tmp.mp4"));
    // destroyed without Finish(): nothing is left behind
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(dir_ + "/atomic.tmp.mp4"));
  VideoRenderer r(plant_->model(), path);
  Feed(r, 0.5, 0.5);
  r.Finish();
  EXPECT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(dir_ + "/atomic.tmp.mp4"));
}

TEST_F(VideoRendererTest, RejectsBadOutputSizeAndDecreasingTime) {
  EXPECT_THROW(VideoRenderer(plant_->model(), dir_ + "/no/such/dir/x.mp4"), InputError);
  RenderOptions odd;
  odd.width = 641;
  EXPECT_THROW(VideoRenderer(plant_->model(), dir_ + "/odd.mp4", odd), InputError);
  VideoRenderer r(plant_->model(), dir_ + "/t.mp4");
  OverlaySample s;
  s.t = 1.0;
  r.AddSample(s);
  s.t = 0.5;
  EXPECT_THROW(r.AddSample(s), std::invalid_argument);
}

}  // namespace
}  // namespace exotwin
