// The leg's pixels are where the kinematics say: world points of the human limb and the exoskeleton,
// computed by MuJoCo's forward kinematics, are projected with render/pixel_projection and must land
// on pixels of that segment's colour, in two or more poses; points away from the leg must not.
#include "render/pixel_projection.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>

#include "render/scene_renderer.h"
#include "sim/plant.h"
#include "tests/render/render_test_util.h"

namespace exotwin {
namespace {

using testing::FractionNear;
using testing::IsExo;
using testing::IsSkin;

class PixelProjection : public ::testing::Test {
 protected:
  void SetUp() override {
    plant_ = std::make_unique<Plant>(ShippedModelPath("leg_exowheel.xml"));
    m_ = plant_->model();
    renderer_ = std::make_unique<SceneRenderer>(m_, RenderOptions{});
    d_ = mj_makeData(m_);
  }
  void TearDown() override { mj_deleteData(d_); }

  // World position of a point given in a geom's local frame, for the pose (q_hip, q_knee).
  void GeomPoint(const char* geom, double lx, double ly, double lz, double out[3]) {
    const int g = mj_name2id(m_, mjOBJ_GEOM, geom);
    ASSERT_GE(g, 0) << geom;
    const double local[3] = {lx, ly, lz};
    mju_mulMatVec(out, d_->geom_xmat + 9 * g, local, 3, 3);
    for (int i = 0; i < 3; ++i) out[i] += d_->geom_xpos[3 * g + i];
  }
  // World position of a point given in a body's frame.
  void BodyPoint(const char* body, double lx, double ly, double lz, double out[3]) {
    const int b = mj_name2id(m_, mjOBJ_BODY, body);
    ASSERT_GE(b, 0) << body;
    const double local[3] = {lx, ly, lz};
    mju_mulMatVec(out, d_->xmat + 9 * b, local, 3, 3);
    for (int i = 0; i < 3; ++i) out[i] += d_->xpos[3 * b + i];
  }
  const cv::Mat& RenderPose(double q_hip, double q_knee) {
    d_->qpos[m_->jnt_qposadr[mj_name2id(m_, mjOBJ_JOINT, "hip")]] = q_hip;
    d_->qpos[m_->jnt_qposadr[mj_name2id(m_, mjOBJ_JOINT, "knee")]] = q_knee;
    mj_kinematics(m_, d_);
    return renderer_->Render(d_->qpos);
  }

  std::unique_ptr<Plant> plant_;
  const mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  std::unique_ptr<SceneRenderer> renderer_;
};

TEST_F(PixelProjection, CameraLooksAlongMinusYAtTheSagittalPlane) {
  const CameraView& v = renderer_->view();
  EXPECT_NEAR(v.forward[1], -1.0, 1e-6);
  EXPECT_NEAR(v.up[2], 1.0, 1e-6);
  EXPECT_GT(v.pos[1], 0.5);  // camera on +y, exoskeleton (y = +0.09) faces it
  // A point straight ahead of the camera projects to the image centre.
  const double ahead[3] = {v.pos[0] + 2 * v.forward[0], v.pos[1] + 2 * v.forward[1], v.pos[2] + 2 * v.forward[2]};
  const PixelPoint p = ProjectToPixel(v, ahead);
  EXPECT_TRUE(p.inside);
  EXPECT_NEAR(p.u, v.width / 2.0, 1e-6);
  EXPECT_NEAR(p.v, v.height / 2.0, 1e-6);
  const double behind[3] = {v.pos[0], v.pos[1] + 1.0, v.pos[2]};
  EXPECT_FALSE(ProjectToPixel(v, behind).inside);
}

TEST_F(PixelProjection, LegPixelsAreWhereTheKinematicsSay) {
  struct Pose {
    double hip, knee;
  };
  // hanging; seated (hip 90 deg, knee -90 deg); extended forward; hip extended, knee flexed
  for (const Pose pose : {Pose{0.0, 0.0}, Pose{M_PI / 2, -M_PI / 2}, Pose{1.2, -0.1}, Pose{-0.3, -1.2}}) {
    SCOPED_TRACE("pose hip " + std::to_string(pose.hip) + " knee " + std::to_string(pose.knee));
    const cv::Mat& img = RenderPose(pose.hip, pose.knee);
    const CameraView& view = renderer_->view();
    double p[3];
    // Foot (human, skin): 0.12 m forward of the shank axis on the foot capsule (shank frame
    // z = -0.5 m), clear of the exoskeleton bar.
    BodyPoint("human_shank", 0.12, 0.0, -0.5, p);
    PixelPoint px = ProjectToPixel(view, p);
    ASSERT_TRUE(px.inside);
    EXPECT_GT(FractionNear(img, px.u, px.v, 2, IsSkin), 0.8) << "foot at " << px.u << "," << px.v;
    // Shank (human): 0.035 m either side of the capsule axis; the exoskeleton bar (0.09 m nearer the
    // camera, so shifted by parallax) may cover one side, never both.
    double best = 0;
    for (double side : {-0.035, 0.035}) {
      GeomPoint("human_shank_geom", side, 0.0, 0.0, p);
      px = ProjectToPixel(view, p);
      best = std::max(best, FractionNear(img, px.u, px.v, 1, IsSkin));
    }
    EXPECT_GT(best, 0.8) << "shank";
    // Exoskeleton bars (blue), centre of the thigh and shank bars.
    for (const char* bar : {"exo_thigh_bar", "exo_shank_bar"}) {
      GeomPoint(bar, 0.0, 0.03, 0.0, p);  // face towards the camera
      px = ProjectToPixel(view, p);
      EXPECT_GT(FractionNear(img, px.u, px.v, 2, IsExo), 0.8) << bar << " at " << px.u << "," << px.v;
    }
    // Away from the leg: 0.35 m behind the shank centre (shank frame -x; the foot points to +x)
    // there is neither skin nor exoskeleton.
    GeomPoint("human_shank_geom", -0.35, 0.0, 0.0, p);
    px = ProjectToPixel(view, p);
    EXPECT_LT(FractionNear(img, px.u, px.v, 3, [](const cv::Vec3b& c) { return IsSkin(c) || IsExo(c); }), 0.05)
        << "empty point at " << px.u << "," << px.v;
  }
}

TEST_F(PixelProjection, ProjectedKneeMovesWithTheHip) {
  RenderPose(0.0, 0.0);
  double knee0[3];
  renderer_->BodyPosition(mj_name2id(m_, mjOBJ_BODY, "exo_shank"), knee0);
  const PixelPoint a = ProjectToPixel(renderer_->view(), knee0);
  RenderPose(M_PI / 2, 0.0);
  double knee1[3];
  renderer_->BodyPosition(mj_name2id(m_, mjOBJ_BODY, "exo_shank"), knee1);
  const PixelPoint b = ProjectToPixel(renderer_->view(), knee1);
  // Hip flexion brings the knee forward (+x = image left for this camera) and up.
  EXPECT_LT(b.u, a.u - 50);
  EXPECT_LT(b.v, a.v - 50);
}

}  // namespace
}  // namespace exotwin
