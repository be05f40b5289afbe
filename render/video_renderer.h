// Videos of the twin: the caller feeds states at the physics rate (e.g. 1 kHz); the renderer draws
// only at frame times k / fps (never every physics step), adds the overlays and encodes an MP4.
// Built into the rendering plugin (render/render_plugin.h opens it as a VideoSink) and linked
// directly only by tests/render and bench/.
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "render/overlay.h"
#include "render/render_options.h"
#include "render/video_sink.h"

struct mjModel_;
struct mjData_;

namespace exotwin {

class Mp4Writer;
class SceneRenderer;

class VideoRenderer final : public VideoSink {
 public:
  // Renders model `m` (copied; see SceneRenderer) into `out_path` (MP4). Throws InputError for an
  // unwritable path, a non-positive fps or an odd/too small frame size; std::runtime_error if OpenGL
  // or the encoder cannot be set up.
  VideoRenderer(const mjModel_* m, const std::string& out_path, const RenderOptions& opt = {});
  ~VideoRenderer() override;  // without Finish(): no file is left behind
  VideoRenderer(const VideoRenderer&) = delete;
  VideoRenderer& operator=(const VideoRenderer&) = delete;

  // VideoSink (render/video_sink.h).
  void AddSample(const mjData_* d, const OverlaySample& s) override;
  void AddSample(const OverlaySample& s) override;
  void Finish(double t_end = std::numeric_limits<double>::quiet_NaN()) override;
  long frames() const override;
  const std::string& codec() const override;
  const RenderStats& stats() const override { return stats_; }

  SceneRenderer& scene() { return *scene_; }   // the renderer (camera view for pixel projection)

 private:
  void Feed(const double* qpos, const OverlaySample& s);
  void EmitFramesBefore(double t_limit);  // frames with time < t_limit, from the last state
  double FrameTime(long k) const { return t0_ + k / opt_.fps; }

  RenderOptions opt_;
  std::unique_ptr<SceneRenderer> scene_;
  std::unique_ptr<Mp4Writer> writer_;
  OverlayHistory history_;
  std::vector<double> qpos_;
  int nq_ = 0, hip_adr_ = -1, knee_adr_ = -1;
  bool started_ = false;
  double t0_ = 0, last_t_ = 0;
  long next_frame_ = 0;
  std::vector<double> last_qpos_;  // state of the latest sample (empty before the first)
  bool finished_ = false;
  RenderStats stats_;
};

}  // namespace exotwin
