// What the video overlays show at one instant (render/overlay.h draws it). Plain data, no OpenCV:
// the runner and the app fill it without loading the rendering stack (render/render_plugin.h).
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// SI units; NaN in tau_est = no estimate.
struct OverlaySample {
  double t = 0;                     // s
  double q_hip = 0, q_knee = 0;     // rad
  double tau_meas[2] = {0, 0};      // measured torque (sensor), N m; [0] hip, [1] knee
  double tau_est[2] = {0, 0};       // the twin's estimate, N m
  std::vector<double> emg;          // EMG envelopes, V (optional; labels in RenderOptions::emg_names)
  std::string event;                // non-empty: a fault event raised at t
};

}  // namespace exotwin
