// Off-screen rendering of a MuJoCo model from the side-view camera into an OpenCV image.
#pragma once
#include <memory>

#include <opencv2/core.hpp>

#include "render/pixel_projection.h"
#include "render/render_options.h"

struct mjModel_;
struct mjData_;

namespace exotwin {

class OsMesaContext;

class SceneRenderer {
 public:
  // Copies `m` (the caller's model may be freed afterwards; later parameter changes are not seen),
  // creates its own OSMesa context and MuJoCo render context. Throws std::runtime_error if OpenGL
  // cannot be set up, std::invalid_argument for a bad size.
  SceneRenderer(const mjModel_* m, const RenderOptions& opt);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Renders the pose qpos (model nq values, as mjData::qpos) and returns a top-down BGR 8-bit image
  // of width x height px (valid until the next call). Must run on the thread that constructed it.
  const cv::Mat& Render(const double* qpos);

  // The camera as used for rendering (for pixel projection).
  const CameraView& view() const { return view_; }
  // World position (m) of a body after the last Render (or of qpos0 before); -1 id throws.
  void BodyPosition(int body_id, double out[3]) const;
  const mjModel_* model() const { return m_; }

 private:
  struct Gl;  // mjvScene, mjvCamera, mjvOption, mjrContext
  void FrameCamera();

  RenderOptions opt_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::unique_ptr<OsMesaContext> osmesa_;
  std::unique_ptr<Gl> gl_;
  CameraView view_{};
  cv::Mat rgb_, bgra_, bgr_;  // read-back (RGB multisampled, BGRA otherwise) and the BGR frame
  bool top_down_ = false;     // GL_MESA_pack_invert accepted: read-back rows come top-down
};

}  // namespace exotwin
