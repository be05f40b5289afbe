#include "render/scene_renderer.h"

#include <GL/gl.h>
#include <GL/glext.h>
#include <dlfcn.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/units.h"
#include "render/osmesa_context.h"

namespace exotwin {

struct SceneRenderer::Gl {
  mjvScene scn;
  mjvCamera cam;
  mjvOption opt;
  mjrContext con;
};

SceneRenderer::SceneRenderer(const mjModel_* m, const RenderOptions& opt) : opt_(opt) {
  if (!m) throw std::invalid_argument("render: null model");
  if (opt.width <= 0 || opt.height <= 0 || opt.width > 8192 || opt.height > 8192)
    throw std::invalid_argument("render: image size must be in 1..8192 px, got " +
                                std::to_string(opt.width) + "x" + std::to_string(opt.height));
  // MuJoCo's GL loader prefers a visible eglGetProcAddress over OSMesa's (see osmesa_context.h):
  // fail clearly here instead of inside mjr_makeContext, which would exit the process.
  if (dlsym(RTLD_DEFAULT, "eglGetProcAddress"))
    throw std::runtime_error("render: libEGL is loaded globally in this process, so MuJoCo would take "
                             "its GL functions from EGL instead of OSMesa; do not link libEGL");
  osmesa_ = std::make_unique<OsMesaContext>(opt.width, opt.height);
  m_ = mj_copyModel(nullptr, m);
  if (!m_) throw std::runtime_error("render: cannot copy the model");
  // The off-screen framebuffer takes its size and multisampling from the model.
  m_->vis.global.offwidth = opt.width;
  m_->vis.global.offheight = opt.height;
  m_->vis.quality.offsamples = std::max(0, opt.multisamples);
  // The model's light shines from -y; the camera looks from +y, so the headlight does the lighting.
  for (int i = 0; i < 3; ++i) {
    m_->vis.headlight.ambient[i] = 0.3f;
    m_->vis.headlight.diffuse[i] = 0.6f;
    m_->vis.headlight.specular[i] = 0.2f;
  }
  d_ = mj_makeData(m_);
  mj_fwdPosition(m_, d_);

  gl_ = std::make_unique<Gl>();
  mjv_defaultScene(&gl_->scn);
  mjv_defaultCamera(&gl_->cam);
  mjv_defaultOption(&gl_->opt);
  mjr_defaultContext(&gl_->con);
  mjv_makeScene(m_, &gl_->scn, 1000);
  mjr_makeContext(m_, &gl_->con, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &gl_->con);
  if (gl_->con.currentBuffer != mjFB_OFFSCREEN || gl_->con.offWidth != opt.width ||
      gl_->con.offHeight != opt.height) {
    mjr_freeContext(&gl_->con);
    mjv_freeScene(&gl_->scn);
    mj_deleteData(d_);
    mj_deleteModel(m_);
    throw std::runtime_error("render: MuJoCo could not create a " + std::to_string(opt.width) + "x" +
                             std::to_string(opt.height) + " off-screen framebuffer under OSMesa");
  }
  gl_->scn.flags[mjRND_SHADOW] = opt.shadows;
  gl_->scn.flags[mjRND_REFLECTION] = 0;
  gl_->scn.flags[mjRND_SKYBOX] = 0;
  FrameCamera();
  // Read-back rows top-down (GL_MESA_pack_invert), so no flip pass; without it, flipped after.
  while (glGetError() != GL_NO_ERROR) {
  }
  glPixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);
  top_down_ = glGetError() == GL_NO_ERROR;
  if (gl_->con.offSamples > 0) rgb_.create(opt.height, opt.width, CV_8UC3);
  else bgra_.create(opt.height, opt.width, CV_8UC4);
  bgr_.create(opt.height, opt.width, CV_8UC3);
}

SceneRenderer::~SceneRenderer() {
  osmesa_->MakeCurrent();
  mjr_freeContext(&gl_->con);
  mjv_freeScene(&gl_->scn);
  mj_deleteData(d_);
  mj_deleteModel(m_);
}

void SceneRenderer::FrameCamera() {
  mjvCamera& cam = gl_->cam;
  cam.type = mjCAMERA_FREE;
  cam.azimuth = opt_.azimuth_deg;
  cam.elevation = opt_.elevation_deg;
  if (!opt_.auto_frame) {
    for (int i = 0; i < 3; ++i) cam.lookat[i] = opt_.lookat[i];
    cam.distance = opt_.distance;
  } else {
    // Hip = body of the joint named "hip" (else the first joint, else the model centre); reach R =
    // farthest extent of a moving geom from the hip. The frame holds the hanging leg, the leg
    // extended forward and a flexed knee behind the hip, with the hip at 42 % of the width so that
    // the strip charts (right-hand third) cover only what lies well behind the seat.
    int jnt = mj_name2id(m_, mjOBJ_JOINT, "hip");
    if (jnt < 0 && m_->njnt > 0) jnt = 0;
    double hip[3] = {m_->stat.center[0], m_->stat.center[1], m_->stat.center[2]};
    if (jnt >= 0) mju_copy3(hip, d_->xanchor + 3 * jnt);
    double reach = 0;
    for (int g = 0; g < m_->ngeom; ++g) {
      if (m_->geom_bodyid[g] == 0 || m_->geom_type[g] == mjGEOM_PLANE) continue;
      double diff[3];
      mju_sub3(diff, d_->geom_xpos + 3 * g, hip);
      reach = std::max(reach, mju_norm3(diff) + m_->geom_rbound[g]);
    }
    if (reach <= 0) reach = m_->stat.extent;
    const double fovy = m_->vis.global.fovy * kRadPerDeg;
    cam.distance = 0.8 * reach / std::tan(0.5 * fovy);
    const double half_w = 0.8 * reach * opt_.width / opt_.height;
    // Image "right" is -x for the default azimuth: shift lookat backward so the hip sits left of centre.
    const double az = opt_.azimuth_deg * kRadPerDeg;
    const double right[3] = {std::sin(az), -std::cos(az), 0.0};  // forward x up, elevation ignored
    for (int i = 0; i < 3; ++i) cam.lookat[i] = hip[i] + 0.16 * half_w * right[i];
    cam.lookat[2] = hip[2] - 0.3 * reach;
  }
  mjv_updateCamera(m_, d_, &cam, &gl_->scn);
  const mjvGLCamera avg = mjv_averageCamera(gl_->scn.camera, gl_->scn.camera + 1);
  view_ = MakeCameraView(avg, opt_.width, opt_.height);
}

const cv::Mat& SceneRenderer::Render(const double* qpos) {
  osmesa_->MakeCurrent();
  mju_copy(d_->qpos, qpos, m_->nq);
  mj_fwdPosition(m_, d_);
  mjv_updateScene(m_, d_, &gl_->opt, nullptr, &gl_->cam, mjCAT_ALL, &gl_->scn);
  const mjrRect viewport = {0, 0, opt_.width, opt_.height};
  mjr_setBuffer(mjFB_OFFSCREEN, &gl_->con);
  mjr_render(viewport, &gl_->scn, &gl_->con);
  // OpenCV wants top-down BGR. Single-sampled, the off-screen framebuffer mjr_setBuffer bound is
  // read in llvmpipe's own layout, BGRA (a copy; RGB costs a per-pixel repack), then the alpha is
  // dropped; multisampled, mjr_readPixels resolves it first and returns RGB.
  if (gl_->con.offSamples == 0) {
    glReadPixels(0, 0, opt_.width, opt_.height, GL_BGRA, GL_UNSIGNED_BYTE, bgra_.data);
    cv::cvtColor(bgra_, bgr_, cv::COLOR_BGRA2BGR);
  } else {
    mjr_readPixels(rgb_.data, nullptr, viewport, &gl_->con);
    cv::cvtColor(rgb_, bgr_, cv::COLOR_RGB2BGR);
  }
  if (!top_down_) cv::flip(bgr_, bgr_, 0);  // OpenGL rows are bottom-up
  const mjvGLCamera avg = mjv_averageCamera(gl_->scn.camera, gl_->scn.camera + 1);
  view_ = MakeCameraView(avg, opt_.width, opt_.height);
  return bgr_;
}

void SceneRenderer::BodyPosition(int body_id, double out[3]) const {
  if (body_id < 0 || body_id >= m_->nbody)
    throw std::invalid_argument("render: no body with id " + std::to_string(body_id));
  mju_copy3(out, d_->xpos + 3 * body_id);
}

}  // namespace exotwin
