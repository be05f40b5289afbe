#include "render/mp4_writer.h"

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

int FourCC(const std::string& c) {
  if (c.size() != 4) throw std::invalid_argument("render: FourCC must have 4 characters, got '" + c + "'");
  return cv::VideoWriter::fourcc(c[0], c[1], c[2], c[3]);
}

}  // namespace

Mp4Writer::Mp4Writer(const std::string& path, double fps, cv::Size size, const std::string& codec)
    : path_(path), tmp_path_(TempPath(path)), size_(size) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError("video output: empty file name");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw InputError(path + ": cannot write the video: folder '" + parent.string() + "' does not exist");
  if (!(fps > 0)) throw InputError(path + ": frame rate must be positive");
  for (const std::string& c : {codec, std::string("mp4v")}) {
    if (writer_.open(tmp_path_, cv::CAP_FFMPEG, FourCC(c), fps, size_, true)) {
      codec_ = c;
      break;
    }
    if (c != "mp4v")
      std::fprintf(stderr,
                   "exotwin: WARNING: the '%s' (H.264) encoder is unavailable in this OpenCV/FFmpeg; "
                   "falling back to 'mp4v' (MPEG-4 Part 2)\n", c.c_str());
    if (c == codec && codec == "mp4v") break;
  }
  if (codec_.empty()) {
    std::error_code ec;
    fs::remove(tmp_path_, ec);
    throw std::runtime_error(path + ": OpenCV/FFmpeg could not open an MP4 encoder ('" + codec + "' or 'mp4v')");
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
  writer_.release();
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
    writer_.write(f);
    std::lock_guard<std::mutex> lock(mu_);
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
  writer_.release();
  closed_ = true;
  std::error_code ec;
  std::filesystem::rename(tmp_path_, path_, ec);
  if (ec) throw std::runtime_error(path_ + ": cannot move the finished video into place: " + ec.message());
}

}  // namespace exotwin
