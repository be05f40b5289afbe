// Videos of the twin: the caller feeds states at the physics rate (e.g. 1 kHz); the renderer draws
// only at frame times k / fps (never every physics step), adds the overlays and encodes an MP4.
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "render/overlay.h"
#include "render/render_options.h"

struct mjModel_;
struct mjData_;

namespace exotwin {

class Mp4Writer;
class SceneRenderer;

// Time spent per stage, summed over the frames written (s).
struct RenderStats {
  long frames = 0;
  double render_s = 0, overlay_s = 0, encode_wait_s = 0;
};

class VideoRenderer {
 public:
  // Renders model `m` (copied; see SceneRenderer) into `out_path` (MP4). Throws InputError for an
  // unwritable path, a non-positive fps or an odd/too small frame size; std::runtime_error if OpenGL
  // or the encoder cannot be set up.
  VideoRenderer(const mjModel_* m, const std::string& out_path, const RenderOptions& opt = {});
  ~VideoRenderer();  // without Finish(): no file is left behind
  VideoRenderer(const VideoRenderer&) = delete;
  VideoRenderer& operator=(const VideoRenderer&) = delete;

  // Feeds one state (d->qpos, model nq values) with its overlay data; s.t (s) must not decrease.
  // Frame k, at time T_k = t0 + k / fps (t0 = first sample's time), shows the latest state with
  // t <= T_k (sample and hold, never a future state); it is rendered once a later sample or Finish
  // shows that no other state can claim it. A state held over several frame times is rendered once.
  void AddSample(const mjData_* d, const OverlaySample& s);
  // Same, with the pose taken from s.q_hip and s.q_knee (hinges named "hip" and "knee"; other joints
  // at qpos0). For replaying measured data.
  void AddSample(const OverlaySample& s);
  // Emits the remaining frames, closes the video and renames it into place. Idempotent. Without
  // t_end the last frame is the last one at or before the last sample; with t_end (s; e.g. last
  // sample time + sample period) every frame time before t_end is filled with the last state, so a
  // record of duration D gives round(D * fps) frames.
  void Finish(double t_end = std::numeric_limits<double>::quiet_NaN());

  long frames() const;                         // frames written so far
  const std::string& codec() const;            // FourCC in use ("avc1" or the "mp4v" fallback)
  const RenderStats& stats() const { return stats_; }
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
