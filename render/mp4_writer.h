// Writes BGR frames to an MP4 file through FFmpeg's libavcodec/libavformat on a worker thread
// (encoding overlaps with rendering). The file appears atomically: frames go to PATH-without-.mp4 +
// ".tmp.mp4", renamed to PATH by Close(); a writer destroyed without Close() removes the temporary
// file. H.264 is libx264 at constant quality (CRF 18, visually lossless) with the "superfast" preset
// on one thread: OpenCV's VideoWriter, used before, passes the codec no options, so x264 ran its
// default "medium" preset at 1.5 x fps x width x height bit/s, about 40 % of a frame's CPU time at
// 1280x720 (now about a quarter of a smaller total), and its frames were no closer to the picture.
#pragma once
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

namespace exotwin {

class Mp4Writer {
 public:
  // Opens the encoder: FourCC `codec` first ("avc1" = H.264, "mp4v" = MPEG-4 Part 2), then "mp4v"
  // with a warning on stderr. fps > 0; size in px (even). Throws InputError if PATH's folder does not
  // exist, runtime_error if no codec opens.
  Mp4Writer(const std::string& path, double fps, cv::Size size, const std::string& codec = "avc1");
  ~Mp4Writer();
  Mp4Writer(const Mp4Writer&) = delete;
  Mp4Writer& operator=(const Mp4Writer&) = delete;

  // Queues a copy of a BGR CV_8UC3 frame of the writer's size; blocks while kMaxQueued frames are
  // queued. The copies go to buffers the encoder has finished with (at most kMaxQueued + 2 exist).
  void Write(const cv::Mat& frame);
  // Flushes the queue and the encoder, closes the file and renames it to PATH. Idempotent.
  void Close();

  const std::string& codec() const { return codec_; }  // FourCC actually used
  long frames() const { return frames_; }               // frames queued so far
  const std::string& path() const { return path_; }

 private:
  struct Encoder;  // FFmpeg state (render/mp4_writer.cc)
  static constexpr size_t kMaxQueued = 4;
  void Run();

  std::string path_, tmp_path_, codec_;
  cv::Size size_;
  std::unique_ptr<Encoder> enc_;
  std::thread worker_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<cv::Mat> queue_;  // frames waiting for the encoder
  std::vector<cv::Mat> free_;   // buffers the encoder is done with, reused by Write
  bool stop_ = false, closed_ = false;
  std::string error_;           // first encoder error (worker thread), reported by Close
  long frames_ = 0;
};

}  // namespace exotwin
