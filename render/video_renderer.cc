#include "render/video_renderer.h"

#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "render/mp4_writer.h"
#include "render/scene_renderer.h"

namespace exotwin {
namespace {

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr double kTimeEps = 1e-9;  // s; sample and frame times closer than this coincide

int HingeQposAdr(const mjModel* m, const char* name) {
  const int j = mj_name2id(m, mjOBJ_JOINT, name);
  return j >= 0 && m->jnt_type[j] == mjJNT_HINGE ? m->jnt_qposadr[j] : -1;
}

}  // namespace

VideoRenderer::VideoRenderer(const mjModel_* m, const std::string& out_path, const RenderOptions& opt)
    : opt_(opt), history_(opt) {
  if (!(opt.fps > 0) || !std::isfinite(opt.fps))
    throw InputError("video: frame rate must be positive and finite, got " + std::to_string(opt.fps));
  if (opt.width < 16 || opt.height < 16 || opt.width % 2 || opt.height % 2)
    throw InputError("video: frame size must be even and at least 16x16 px (H.264 4:2:0), got " +
                     std::to_string(opt.width) + "x" + std::to_string(opt.height));
  writer_ = std::make_unique<Mp4Writer>(out_path, opt.fps, cv::Size(opt.width, opt.height), opt.codec);
  scene_ = std::make_unique<SceneRenderer>(m, opt);
  nq_ = m->nq;
  qpos_.assign(m->qpos0, m->qpos0 + m->nq);
  hip_adr_ = HingeQposAdr(m, "hip");
  knee_adr_ = HingeQposAdr(m, "knee");
}

VideoRenderer::~VideoRenderer() = default;

void VideoRenderer::AddSample(const mjData_* d, const OverlaySample& s) {
  if (!d) throw std::invalid_argument("render: null mjData");
  Feed(d->qpos, s);
}

void VideoRenderer::AddSample(const OverlaySample& s) {
  if (hip_adr_ < 0 || knee_adr_ < 0)
    throw std::invalid_argument("render: the model has no hinge joints named 'hip' and 'knee'");
  qpos_[hip_adr_] = s.q_hip;
  qpos_[knee_adr_] = s.q_knee;
  Feed(qpos_.data(), s);
}

void VideoRenderer::Feed(const double* qpos, const OverlaySample& s) {
  if (!std::isfinite(s.t)) throw std::invalid_argument("render: sample time is not finite");
  if (!started_) {
    started_ = true;
    t0_ = last_t_ = s.t;
  }
  if (s.t < last_t_)
    throw std::invalid_argument("render: sample times must not decrease (" + std::to_string(s.t) +
                                " after " + std::to_string(last_t_) + ")");
  // Frames strictly before this sample show the previous sample (the latest at or before them).
  EmitFramesBefore(s.t - kTimeEps);
  last_t_ = s.t;
  last_qpos_.assign(qpos, qpos + nq_);
  history_.Add(s);
}

void VideoRenderer::EmitFramesBefore(double t_limit) {
  if (last_qpos_.empty() || FrameTime(next_frame_) >= t_limit) return;
  // Render once; repeat that frame for every frame time up to t_limit.
  const double a = Now();
  cv::Mat frame = scene_->Render(last_qpos_.data());  // the renderer's buffer; overlays draw into it
  const double b = Now();
  if (opt_.overlays) history_.Draw(frame);
  const double c = Now();
  while (FrameTime(next_frame_) < t_limit) {
    writer_->Write(frame);
    ++next_frame_;
    ++stats_.frames;
  }
  stats_.render_s += b - a;
  stats_.overlay_s += c - b;
  stats_.encode_wait_s += Now() - c;
}

void VideoRenderer::Finish(double t_end) {
  if (!finished_) EmitFramesBefore(std::isfinite(t_end) ? t_end - kTimeEps : last_t_ + kTimeEps);
  finished_ = true;
  writer_->Close();
}

long VideoRenderer::frames() const { return writer_->frames(); }
const std::string& VideoRenderer::codec() const { return writer_->codec(); }

}  // namespace exotwin
