// Options of the off-screen renderer and the video it writes.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

struct RenderOptions {
  int width = 1280, height = 720;  // px; the MuJoCo off-screen buffer is resized to match
  double fps = 30.0;               // frames per second of simulated time (> 0)
  std::string codec = "avc1";      // FourCC tried first (H.264); "mp4v" is the fallback

  // Image quality vs speed with the llvmpipe software rasterizer (1280x720, 2 cores): shadows double
  // the render time and multisampling adds ~15 ms per frame, so both are off by default.
  bool shadows = false;
  int multisamples = 0;

  // Side view of the sagittal (x-z) plane. Azimuth -90 deg puts the camera on +y looking along -y,
  // so the exoskeleton (y > 0) is in front of the limb; forward (+x) is to the left of the image.
  double azimuth_deg = -90.0, elevation_deg = 0.0;
  bool auto_frame = true;        // choose lookat and distance from the model's hip and leg length
  double lookat[3] = {0, 0, 0};  // m, world; used when auto_frame is false
  double distance = 2.0;         // m; used when auto_frame is false

  bool overlays = true;                 // text, strip charts, events
  double chart_window_s = 4.0;          // time span of the strip charts (s)
  std::vector<std::string> emg_names;   // labels of OverlaySample::emg channels (optional)
  // Key of the legs drawn (optional), under the angles: a swatch of colour rgb (0..1) per label.
  struct LegendEntry {
    std::string label;
    double rgb[3] = {1, 1, 1};
  };
  std::vector<LegendEntry> legend;
};

}  // namespace exotwin
