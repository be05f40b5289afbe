#include "render/mp4_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <climits>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "core/error.h"

namespace exotwin {
namespace {

std::string TempPath(const std::string& path) {
  const std::string ext = ".mp4";
  std::string stem = path;
  if (stem.size() > ext.size() && stem.compare(stem.size() - ext.size(), ext.size(), ext) == 0)
    stem.resize(stem.size() - ext.size());
  return stem + ".tmp.mp4";
}

}  // namespace

// One open MP4 file with one video stream; frames in, packets muxed out.
struct Mp4Writer::Encoder {
  AVFormatContext* oc = nullptr;
  AVStream* st = nullptr;
  AVCodecContext* ctx = nullptr;
  AVFrame* frame = nullptr;  // YUV 4:2:0 picture handed to the codec
  AVPacket* pkt = nullptr;
  SwsContext* sws = nullptr;  // BGR24 -> YUV420P
  int64_t next_pts = 0;       // in frames (codec time base 1 / fps)

  ~Encoder() {
    sws_freeContext(sws);
    av_frame_free(&frame);
    av_packet_free(&pkt);
    avcodec_free_context(&ctx);
    if (oc) {
      if (oc->pb) avio_closep(&oc->pb);
      avformat_free_context(oc);
    }
  }

  // Opens `file` for FourCC "avc1" (libx264) or "mp4v" (MPEG-4 Part 2); nullptr if FFmpeg cannot.
  static std::unique_ptr<Encoder> Open(const std::string& file, const std::string& fourcc, double fps, cv::Size size) {
    const AVCodec* codec = fourcc == "avc1"   ? avcodec_find_encoder_by_name("libx264")
                           : fourcc == "mp4v" ? avcodec_find_encoder(AV_CODEC_ID_MPEG4)
                                              : nullptr;
    if (!codec) return nullptr;
    auto e = std::make_unique<Encoder>();
    if (avformat_alloc_output_context2(&e->oc, nullptr, "mp4", file.c_str()) < 0 || !e->oc) return nullptr;
    e->st = avformat_new_stream(e->oc, nullptr);
    e->ctx = avcodec_alloc_context3(codec);
    e->frame = av_frame_alloc();
    e->pkt = av_packet_alloc();
    if (!e->st || !e->ctx || !e->frame || !e->pkt) return nullptr;
    AVCodecContext* c = e->ctx;
    c->width = size.width;
    c->height = size.height;
    c->pix_fmt = AV_PIX_FMT_YUV420P;
    c->framerate = av_d2q(fps, 1000000);
    c->time_base = av_inv_q(c->framerate);
    c->thread_count = 1;  // the encoder has its own thread already; the renderer uses the other cores
    if (fourcc == "avc1") {
      // superfast at CRF 18: visually lossless, ~0.3 MB per second of 1280x720 video; the encoder
      // thread then keeps pace with the renderer at 2x real time on two cores (exotwin bench render).
      av_opt_set(c->priv_data, "preset", "superfast", 0);
      av_opt_set(c->priv_data, "crf", "18", 0);
    } else {
      c->gop_size = 12;
      c->bit_rate = static_cast<int64_t>(std::min(1.5 * fps * size.width * size.height, double(INT_MAX)));
    }
    if (e->oc->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (avcodec_open2(c, codec, nullptr) < 0) return nullptr;
    if (avcodec_parameters_from_context(e->st->codecpar, c) < 0) return nullptr;
    e->st->time_base = c->time_base;
    e->st->avg_frame_rate = c->framerate;
    if (avio_open(&e->oc->pb, file.c_str(), AVIO_FLAG_WRITE) < 0) return nullptr;
    if (avformat_write_header(e->oc, nullptr) < 0) return nullptr;
    e->frame->format = c->pix_fmt;
    e->frame->width = c->width;
    e->frame->height = c->height;
    if (av_frame_get_buffer(e->frame, 0) < 0) return nullptr;
    e->sws = sws_getContext(c->width, c->height, AV_PIX_FMT_BGR24, c->width, c->height, AV_PIX_FMT_YUV420P,
                            SWS_BICUBIC, nullptr, nullptr, nullptr);
    return e->sws ? std::move(e) : nullptr;
  }

  // Converts and encodes one BGR frame; false on an FFmpeg error.
  bool Encode(const cv::Mat& bgr) {
    if (av_frame_make_writable(frame) < 0) return false;
    const uint8_t* src[1] = {bgr.data};
    const int stride[1] = {static_cast<int>(bgr.step)};
    sws_scale(sws, src, stride, 0, bgr.rows, frame->data, frame->linesize);
    frame->pts = next_pts++;
    return Send(frame);
  }

  // Drains the encoder and writes the file's index; false on an FFmpeg error.
  bool Finish() { return Send(nullptr) && av_write_trailer(oc) >= 0; }

 private:
  // Sends a frame (nullptr: end of stream) and muxes every packet the codec has ready.
  bool Send(const AVFrame* f) {
    if (avcodec_send_frame(ctx, f) < 0) return false;
    for (;;) {
      const int r = avcodec_receive_packet(ctx, pkt);
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return true;
      if (r < 0) return false;
      pkt->duration = 1;  // one frame: the muxer then knows the last frame's length too
      av_packet_rescale_ts(pkt, ctx->time_base, st->time_base);
      pkt->stream_index = st->index;
      if (av_interleaved_write_frame(oc, pkt) < 0) return false;
    }
  }
};

Mp4Writer::Mp4Writer(const std::string& path, double fps, cv::Size size, const std::string& codec)
    : path_(path), tmp_path_(TempPath(path)), size_(size) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError("video output: empty file name");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw InputError(path + ": cannot write the video: folder '" + parent.string() + "' does not exist");
  if (!(fps > 0)) throw InputError(path + ": frame rate must be positive");
  if (codec.size() != 4) throw std::invalid_argument("render: FourCC must have 4 characters, got '" + codec + "'");
  av_log_set_level(AV_LOG_ERROR);  // no encoder banners on stderr
  for (const std::string& c : {codec, std::string("mp4v")}) {
    if ((enc_ = Encoder::Open(tmp_path_, c, fps, size_))) {
      codec_ = c;
      break;
    }
    if (c != "mp4v")
      std::fprintf(stderr,
                   "exotwin: WARNING: the '%s' (H.264) encoder is unavailable in this FFmpeg; "
                   "falling back to 'mp4v' (MPEG-4 Part 2)\n", c.c_str());
    if (c == codec && codec == "mp4v") break;
  }
  if (codec_.empty()) {
    std::error_code ec;
    fs::remove(tmp_path_, ec);
    throw std::runtime_error(path + ": FFmpeg could not open an MP4 encoder ('" + codec + "' or 'mp4v')");
  }
  worker_ = std::thread(&Mp4Writer::Run, this);
}

Mp4Writer::~Mp4Writer() {
  if (closed_) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
    queue_.clear();
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  enc_.reset();
  std::error_code ec;
  std::filesystem::remove(tmp_path_, ec);  // never leave a partial video behind
}

void Mp4Writer::Write(const cv::Mat& frame) {
  if (closed_) throw std::logic_error("render: Write after Close");
  if (frame.size() != size_ || frame.type() != CV_8UC3)
    throw std::invalid_argument("render: frame size/type does not match the video");
  std::unique_lock<std::mutex> lock(mu_);
  cv_.wait(lock, [this] { return queue_.size() < kMaxQueued; });
  cv::Mat copy;
  if (!free_.empty()) {
    copy = std::move(free_.back());
    free_.pop_back();
  }
  lock.unlock();
  frame.copyTo(copy);  // into a recycled buffer: no 3 MB allocation (and page faults) per frame
  lock.lock();
  queue_.push_back(std::move(copy));
  ++frames_;
  lock.unlock();
  cv_.notify_all();
}

void Mp4Writer::Run() {
  for (;;) {
    cv::Mat f;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stop_ and drained
      f = std::move(queue_.front());
      queue_.pop_front();
    }
    cv_.notify_all();
    const bool ok = enc_->Encode(f);
    std::lock_guard<std::mutex> lock(mu_);
    if (!ok && error_.empty()) error_ = "FFmpeg failed to encode frame " + std::to_string(enc_->next_pts);
    free_.push_back(std::move(f));
  }
}

void Mp4Writer::Close() {
  if (closed_) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
  const bool ok = enc_->Finish() && error_.empty();
  enc_.reset();
  closed_ = true;
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(tmp_path_, ec);
    throw std::runtime_error(path_ + ": " + (error_.empty() ? "FFmpeg failed to finish the video" : error_));
  }
  std::filesystem::rename(tmp_path_, path_, ec);
  if (ec) throw std::runtime_error(path_ + ": cannot move the finished video into place: " + ec.message());
}

}  // namespace exotwin
