#include "render/overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/units.h"

namespace exotwin {
namespace {

const cv::Scalar kWhite(255, 255, 255), kGrey(150, 150, 150), kMeas(80, 220, 255),
    kEst(255, 160, 60), kEvent(60, 60, 255);
const cv::Scalar kEmgColours[] = {{90, 230, 90}, {230, 90, 230}, {90, 230, 230}, {230, 230, 90},
                                  {160, 160, 255}, {255, 200, 160}};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

// Darkens a rectangle so text on it is readable over the scene.
void Panel(cv::Mat& f, cv::Rect r) {
  r &= cv::Rect(0, 0, f.cols, f.rows);
  if (r.area() > 0) {
    cv::Mat roi = f(r);
    roi.convertTo(roi, -1, 0.35);
  }
}

void Text(cv::Mat& f, const std::string& s, cv::Point p, double scale, const cv::Scalar& c, int thick = 1) {
  cv::putText(f, s, p, kFont, scale, c, thick, cv::LINE_AA);
}

// A "nice" symmetric or offset range holding [lo, hi], at least `min_span` wide.
void NiceRange(double& lo, double& hi, double min_span) {
  if (!(hi >= lo)) lo = -1, hi = 1;
  if (hi - lo < min_span) {
    const double c = 0.5 * (hi + lo);
    lo = c - 0.5 * min_span, hi = c + 0.5 * min_span;
  }
  const double pad = 0.08 * (hi - lo);
  lo -= pad, hi += pad;
}

}  // namespace

void OverlayHistory::Add(const OverlaySample& s) {
  last_ = s;
  has_last_ = true;
  if (!s.event.empty()) events_.push_back({s.t, s.event});
  const double min_dt = opt_.chart_window_s / (0.3 * std::max(opt_.width, 320));  // ~1 point per chart px
  if (points_.empty() || s.t - points_.back().t >= min_dt || s.t < points_.back().t) {
    Point p;
    p.t = s.t;
    for (int j = 0; j < 2; ++j) {
      p.tau_meas[j] = static_cast<float>(s.tau_meas[j]);
      p.tau_est[j] = static_cast<float>(s.tau_est[j]);
    }
    p.emg.assign(s.emg.begin(), s.emg.end());
    points_.push_back(std::move(p));
  }
  while (!points_.empty() && points_.front().t < s.t - opt_.chart_window_s) points_.pop_front();
}

void OverlayHistory::DrawChart(cv::Mat& f, const cv::Rect& r, const std::string& title, int joint) const {
  Panel(f, r);
  const double sc = r.height / 200.0;
  Text(f, title + " torque (N m)", {r.x + 8, r.y + int(22 * sc)}, 0.55 * sc, kWhite);
  Text(f, "measured", {r.x + r.width - int(190 * sc), r.y + int(22 * sc)}, 0.45 * sc, kMeas);
  Text(f, "twin", {r.x + r.width - int(80 * sc), r.y + int(22 * sc)}, 0.45 * sc, kEst);
  const cv::Rect plot(r.x + int(50 * sc), r.y + int(32 * sc), r.width - int(60 * sc), r.height - int(44 * sc));
  double lo = INFINITY, hi = -INFINITY;
  for (const Point& p : points_)
    for (float v : {p.tau_meas[joint], p.tau_est[joint]})
      if (std::isfinite(v)) lo = std::min<double>(lo, v), hi = std::max<double>(hi, v);
  NiceRange(lo, hi, 2.0);
  cv::rectangle(f, plot, kGrey, 1);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", hi);
  Text(f, buf, {r.x + 4, plot.y + int(10 * sc)}, 0.4 * sc, kGrey);
  std::snprintf(buf, sizeof buf, "%.0f", lo);
  Text(f, buf, {r.x + 4, plot.y + plot.height}, 0.4 * sc, kGrey);
  if (lo < 0 && hi > 0) {
    const int y0 = plot.y + int((hi / (hi - lo)) * plot.height);
    cv::line(f, {plot.x, y0}, {plot.x + plot.width, y0}, kGrey, 1);
  }
  const double t1 = has_last_ ? last_.t : 0.0, t0 = t1 - opt_.chart_window_s;
  auto to_px = [&](double t, double v) {
    return cv::Point(plot.x + int((t - t0) / opt_.chart_window_s * plot.width),
                     plot.y + int((hi - v) / (hi - lo) * plot.height));
  };
  for (int series = 0; series < 2; ++series) {
    std::vector<cv::Point> pts;
    pts.reserve(points_.size());
    for (const Point& p : points_) {
      const float v = series == 0 ? p.tau_meas[joint] : p.tau_est[joint];
      if (std::isfinite(v)) pts.push_back(to_px(p.t, v));
    }
    if (pts.size() >= 2)
      // measured wide underneath, the twin thin on top: both stay visible where they agree
      cv::polylines(f, pts, false, series == 0 ? kMeas : kEst,
                    series == 0 ? std::max(2, int(4 * sc)) : std::max(1, int(1.5 * sc)), cv::LINE_AA);
  }
}

void OverlayHistory::DrawEmgChart(cv::Mat& f, const cv::Rect& r) const {
  Panel(f, r);
  const double sc = r.height / 200.0;
  Text(f, "EMG envelopes (V)", {r.x + 8, r.y + int(22 * sc)}, 0.55 * sc, kWhite);
  const size_t nch = last_.emg.size();
  for (size_t c = 0; c < nch; ++c) {
    const std::string name = c < opt_.emg_names.size() ? opt_.emg_names[c] : "ch" + std::to_string(c);
    Text(f, name, {r.x + int((180 + 60 * c) * sc), r.y + int(22 * sc)}, 0.42 * sc, kEmgColours[c % 6]);
  }
  const cv::Rect plot(r.x + int(50 * sc), r.y + int(32 * sc), r.width - int(60 * sc), r.height - int(44 * sc));
  cv::rectangle(f, plot, kGrey, 1);
  double hi = 0;
  for (const Point& p : points_)
    for (float v : p.emg)
      if (std::isfinite(v)) hi = std::max<double>(hi, v);
  if (hi <= 0) hi = 1e-3;
  hi *= 1.1;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", hi);
  Text(f, buf, {r.x + 4, plot.y + int(10 * sc)}, 0.4 * sc, kGrey);
  const double t1 = last_.t, t0 = t1 - opt_.chart_window_s;
  for (size_t c = 0; c < nch; ++c) {
    std::vector<cv::Point> pts;
    for (const Point& p : points_)
      if (c < p.emg.size() && std::isfinite(p.emg[c]))
        pts.emplace_back(plot.x + int((p.t - t0) / opt_.chart_window_s * plot.width),
                         plot.y + int((hi - std::max(0.0f, p.emg[c])) / hi * plot.height));
    if (pts.size() >= 2) cv::polylines(f, pts, false, kEmgColours[c % 6], std::max(1, int(2 * sc)), cv::LINE_AA);
  }
}

void OverlayHistory::Draw(cv::Mat& f) const {
  if (!has_last_) return;
  const double sc = f.rows / 720.0;
  // Time and joint angles (degrees: human-facing text), top left.
  Panel(f, cv::Rect(int(12 * sc), int(12 * sc), int(300 * sc), int(110 * sc)));
  char buf[96];
  std::snprintf(buf, sizeof buf, "t = %7.3f s", last_.t);
  Text(f, buf, {int(24 * sc), int(44 * sc)}, 0.8 * sc, kWhite, std::max(1, int(2 * sc)));
  std::snprintf(buf, sizeof buf, "hip  %+7.1f deg", last_.q_hip * kDegPerRad);
  Text(f, buf, {int(24 * sc), int(78 * sc)}, 0.65 * sc, kWhite);
  std::snprintf(buf, sizeof buf, "knee %+7.1f deg", last_.q_knee * kDegPerRad);
  Text(f, buf, {int(24 * sc), int(108 * sc)}, 0.65 * sc, kWhite);

  // Legend of the legs (e.g. measured and simulated), under the angles.
  if (!opt_.legend.empty()) {
    const int line = int(24 * sc), y0 = int(130 * sc);
    Panel(f, cv::Rect(int(12 * sc), y0, int(300 * sc), int(opt_.legend.size() * line + 10 * sc)));
    for (size_t i = 0; i < opt_.legend.size(); ++i) {
      const auto& e = opt_.legend[i];
      const int y = y0 + int((i + 1) * line);
      const cv::Scalar c(255 * e.rgb[2], 255 * e.rgb[1], 255 * e.rgb[0]);
      cv::rectangle(f, cv::Rect(int(24 * sc), y - int(14 * sc), int(28 * sc), int(14 * sc)), c, cv::FILLED);
      Text(f, e.label, {int(62 * sc), y}, 0.55 * sc, kWhite);
    }
  }

  // Strip charts, right-hand side: hip, knee, then EMG if any channel is present.
  const bool emg = !last_.emg.empty();
  const int n = emg ? 3 : 2;
  const int x = int(f.cols * 0.66), w = f.cols - x - int(12 * sc);
  const int gap = int(10 * sc), top = int(12 * sc);
  const int h = std::min(int(220 * sc), (f.rows - 2 * top - (n - 1) * gap) / n);
  DrawChart(f, cv::Rect(x, top, w, h), "hip", 0);
  DrawChart(f, cv::Rect(x, top + h + gap, w, h), "knee", 1);
  if (emg) DrawEmgChart(f, cv::Rect(x, top + 2 * (h + gap), w, h));

  // Fault events, bottom left: the latest few with their time.
  if (!events_.empty()) {
    const size_t shown = std::min<size_t>(events_.size(), 5);
    const int line = int(26 * sc);
    const int ph = int((shown + 1) * line + 10 * sc);
    const int y0 = f.rows - int(12 * sc) - ph;
    Panel(f, cv::Rect(int(12 * sc), y0, int(560 * sc), ph));
    std::snprintf(buf, sizeof buf, "fault events (%zu)", events_.size());
    Text(f, buf, {int(24 * sc), y0 + line}, 0.6 * sc, kEvent, std::max(1, int(2 * sc)));
    for (size_t i = 0; i < shown; ++i) {
      const auto& e = events_[events_.size() - shown + i];
      std::snprintf(buf, sizeof buf, "%8.3f s  ", e.t);
      Text(f, buf + e.text, {int(24 * sc), y0 + int((i + 2) * line)}, 0.55 * sc, kWhite);
    }
  }
}

}  // namespace exotwin
