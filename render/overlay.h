// Overlays drawn on each video frame with OpenCV: time, joint angles, strip charts of measured vs
// estimated torque (per joint), EMG envelopes, and a list of fault events.
#pragma once
#include <deque>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "render/overlay_sample.h"
#include "render/render_options.h"

namespace exotwin {

// The recent past the strip charts need (decimated to about one point per chart pixel).
class OverlayHistory {
 public:
  explicit OverlayHistory(const RenderOptions& opt) : opt_(opt) {}
  // Appends a sample (t non-decreasing), drops points older than the chart window, records events.
  void Add(const OverlaySample& s);
  // Draws every overlay for the latest sample onto a BGR frame (CV_8UC3) of any size.
  void Draw(cv::Mat& frame) const;

 private:
  struct Point {
    double t;
    float tau_meas[2], tau_est[2];
    std::vector<float> emg;
  };
  struct Event {
    double t;
    std::string text;
  };
  void DrawChart(cv::Mat& f, const cv::Rect& r, const std::string& title, int joint) const;
  void DrawEmgChart(cv::Mat& f, const cv::Rect& r) const;

  RenderOptions opt_;
  std::deque<Point> points_;
  std::vector<Event> events_;
  OverlaySample last_;
  bool has_last_ = false;
};

}  // namespace exotwin
