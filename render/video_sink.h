// A video being rendered, as the runner and the app see it: states in, MP4 out. The implementation
// (render/video_renderer.h: OSMesa, OpenCV) lives in the rendering plugin; render/render_plugin.h
// opens one. This header needs neither OpenGL nor OpenCV.
#pragma once
#include <limits>
#include <string>

#include "render/overlay_sample.h"

struct mjData_;

namespace exotwin {

// Time spent per stage, summed over the frames written (s).
struct RenderStats {
  long frames = 0;
  double render_s = 0, overlay_s = 0, encode_wait_s = 0;
};

class VideoSink {
 public:
  virtual ~VideoSink() = default;  // without Finish(): no file is left behind

  // Feeds one state (d->qpos, model nq values) with its overlay data; s.t (s) must not decrease.
  // Frame k, at time T_k = t0 + k / fps (t0 = first sample's time), shows the latest state with
  // t <= T_k (sample and hold, never a future state); it is rendered once a later sample or Finish
  // shows that no other state can claim it. A state held over several frame times is rendered once.
  virtual void AddSample(const mjData_* d, const OverlaySample& s) = 0;
  // Same, with the pose taken from s.q_hip and s.q_knee (hinges named "hip" and "knee"; other joints
  // at qpos0). For replaying measured data.
  virtual void AddSample(const OverlaySample& s) = 0;
  // Emits the remaining frames, closes the video and renames it into place. Idempotent. Without
  // t_end the last frame is the last one at or before the last sample; with t_end (s; e.g. last
  // sample time + sample period) every frame time before t_end is filled with the last state, so a
  // record of duration D gives round(D * fps) frames.
  virtual void Finish(double t_end = std::numeric_limits<double>::quiet_NaN()) = 0;

  virtual long frames() const = 0;               // frames written so far
  virtual const std::string& codec() const = 0;  // FourCC in use ("avc1" or the "mp4v" fallback)
  virtual const RenderStats& stats() const = 0;
};

}  // namespace exotwin
