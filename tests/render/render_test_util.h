// Helpers shared by the render/ tests: pixel colour classes, leg poses.
#pragma once
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include <opencv2/core.hpp>

namespace exotwin::testing {

// Skin (human segments, rgba 0.93 0.76 0.62): red dominant over blue.
inline bool IsSkin(const cv::Vec3b& bgr) {
  return bgr[2] > 110 && bgr[2] > bgr[0] + 35 && bgr[2] >= bgr[1];
}
// Exoskeleton blue (rgba 0.25 0.45 0.85): blue dominant over red.
inline bool IsExo(const cv::Vec3b& bgr) { return bgr[0] > 80 && bgr[0] > bgr[2] + 35; }

// Fraction of pixels in a (2r+1)^2 window around (u, v) that satisfy pred.
template <class Pred>
double FractionNear(const cv::Mat& img, double u, double v, int r, Pred pred) {
  int hit = 0, n = 0;
  for (int y = int(v) - r; y <= int(v) + r; ++y)
    for (int x = int(u) - r; x <= int(u) + r; ++x) {
      if (x < 0 || y < 0 || x >= img.cols || y >= img.rows) continue;
      ++n;
      hit += pred(img.at<cv::Vec3b>(y, x)) ? 1 : 0;
    }
  return n ? double(hit) / n : 0.0;
}

// Mean absolute difference of two equal-size images inside a rectangle (grey levels).
inline double MeanAbsDiff(const cv::Mat& a, const cv::Mat& b, const cv::Rect& r) {
  cv::Mat d;
  cv::absdiff(a(r), b(r), d);
  const cv::Scalar s = cv::mean(d);
  return (s[0] + s[1] + s[2]) / 3.0;
}

// The test motion: the leg swings for t < t_move (s), then holds still.
inline void TestPose(double t, double t_move, double* q_hip, double* q_knee) {
  const double tt = std::min(t, t_move);
  *q_hip = 0.6 + 0.5 * std::sin(2 * M_PI * 0.8 * tt);
  *q_knee = -0.9 + 0.6 * std::sin(2 * M_PI * 1.1 * tt);
}

}  // namespace exotwin::testing
