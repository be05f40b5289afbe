// Ghost legs (sim/ghost_legs.h) are drawn where their own angles say: world points of each ghost's
// shank, from MuJoCo's forward kinematics of the combined model, are projected with
// render/pixel_projection and land on pixels of that ghost's colour, while the measured leg keeps
// its skin colour at its own pose.
#include "sim/ghost_legs.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>

#include "core/error.h"
#include "render/scene_renderer.h"
#include "sim/plant.h"
#include "tests/render/render_test_util.h"

namespace exotwin {
namespace {

using testing::FractionNear;
using testing::IsSkin;

// Ghost colours over a black background: one channel well above the two others.
bool IsGhostRed(const cv::Vec3b& c) { return c[2] > 70 && c[2] > c[1] + 50 && c[2] > c[0] + 50; }
bool IsGhostGreen(const cv::Vec3b& c) { return c[1] > 70 && c[1] > c[2] + 50 && c[1] > c[0] + 50; }

TEST(GhostLegs, PixelsAreWhereTheirAnglesSay) {
  const std::vector<GhostLegStyle> styles = {{"_ghost1", {0.95, 0.1, 0.1, 0.45}}, {"_ghost2", {0.1, 0.8, 0.2, 0.45}}};
  GhostLegModel ghosts(ShippedModelPath("leg_exowheel.xml"), styles, 0.45);
  const mjModel* m = ghosts.model();
  ASSERT_EQ(ghosts.ghosts(), 2);
  ASSERT_EQ(m->nq, 6);
  // The copies carry the thigh length: each shank sits L1 below its hip.
  for (const char* b : {"exo_shank", "exo_shank_ghost1", "exo_shank_ghost2"})
    EXPECT_DOUBLE_EQ(m->body_pos[3 * mj_name2id(m, mjOBJ_BODY, b) + 2], -0.45) << b;

  // Measured leg hanging; ghost 1 held out forward; ghost 2 thigh back, knee flexed behind.
  ghosts.SetLeg(-1, 0.0, 0.0);
  ghosts.SetLeg(0, 1.5, 0.0);
  ghosts.SetLeg(1, -0.4, -1.5);
  SceneRenderer renderer(m, RenderOptions{});
  const cv::Mat& img = renderer.Render(ghosts.data()->qpos);
  mjData* d = mj_makeData(m);
  mju_copy(d->qpos, ghosts.data()->qpos, m->nq);
  mj_kinematics(m, d);
  auto point = [&](const char* body, double z, double x = 0) {  // x m forward of the shank axis, z m below the knee
    const int b = mj_name2id(m, mjOBJ_BODY, body);
    const double local[3] = {x, 0, -z};
    double w[3];
    mju_mulMatVec(w, d->xmat + 9 * b, local, 3, 3);
    for (int i = 0; i < 3; ++i) w[i] += d->xpos[3 * b + i];
    return ProjectToPixel(renderer.view(), w);
  };
  // The measured leg's foot (skin, clear of its exoskeleton bar, which covers the shank's axis).
  PixelPoint p = point("human_shank", 0.5, 0.12);
  ASSERT_TRUE(p.inside);
  EXPECT_GT(FractionNear(img, p.u, p.v, 2, IsSkin), 0.8) << "measured foot at " << p.u << "," << p.v;
  // A ghost's shank point from its angles alone: its hip is the measured hip moved kGhostStepY * (k + 1)
  // towards the camera (+y); thigh L1 and shank turn about -y (flexion moves the segment to +x).
  const double* hip = d->xanchor + 3 * mj_name2id(m, mjOBJ_JOINT, "hip");
  auto angles_point = [&](int k, double q_hip, double q_knee, double z) {
    const double w[3] = {hip[0] + 0.45 * std::sin(q_hip) + z * std::sin(q_hip + q_knee),
                         hip[1] + GhostLegModel::kGhostStepY * (k + 1),
                         hip[2] - 0.45 * std::cos(q_hip) - z * std::cos(q_hip + q_knee)};
    return ProjectToPixel(renderer.view(), w);
  };
  for (double z : {0.15, 0.3}) {
    SCOPED_TRACE("shank point " + std::to_string(z) + " m below the knee");
    // The model's kinematics agree with the angles (within 2 px).
    for (int k : {0, 1}) {
      const PixelPoint a = point(k == 0 ? "human_shank_ghost1" : "human_shank_ghost2", z);
      const PixelPoint b = k == 0 ? angles_point(0, 1.5, 0.0, z) : angles_point(1, -0.4, -1.5, z);
      EXPECT_NEAR(a.u, b.u, 2.0) << "ghost " << k + 1;
      EXPECT_NEAR(a.v, b.v, 2.0) << "ghost " << k + 1;
    }
    p = angles_point(0, 1.5, 0.0, z);
    ASSERT_TRUE(p.inside);
    EXPECT_GT(FractionNear(img, p.u, p.v, 1, IsGhostRed), 0.8) << "ghost 1 at " << p.u << "," << p.v;
    EXPECT_EQ(FractionNear(img, p.u, p.v, 1, IsGhostGreen), 0.0);
    p = angles_point(1, -0.4, -1.5, z);
    ASSERT_TRUE(p.inside);
    EXPECT_GT(FractionNear(img, p.u, p.v, 1, IsGhostGreen), 0.8) << "ghost 2 at " << p.u << "," << p.v;
  }
  mj_deleteData(d);
}

TEST(GhostLegs, ModelWithoutTheLegIsRefusedNamingTheFile) {
  EXPECT_THROW(AddGhostLegs("<mujoco><worldbody/></mujoco>", "x.xml", {{"_g", {1, 0, 0, 1}}}), InputError);
  try {
    AddGhostLegs("<mujoco><worldbody><body name='exo_thigh'/></worldbody></mujoco>", "x.xml", {{"_g", {1, 0, 0, 1}}});
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.xml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace exotwin
