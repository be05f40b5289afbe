// The rendering plugin's entry point (render/render_plugin_abi.h): the only symbol the module
// exports (render/CMakeLists.txt hides the rest).
#include <opencv2/core.hpp>

#include "render/render_plugin_abi.h"
#include "render/scene_renderer.h"
#include "render/video_renderer.h"

namespace {

exotwin::VideoSink* OpenVideo(const mjModel_* m, const std::string& out_path, const exotwin::RenderOptions& opt) {
  return new exotwin::VideoRenderer(m, out_path, opt);
}

void RenderStill(const mjModel_* m, const double* qpos, const exotwin::RenderOptions& opt,
                 std::vector<unsigned char>* rgb) {
  exotwin::SceneRenderer scene(m, opt);
  const cv::Mat& bgr = scene.Render(qpos);
  rgb->resize(static_cast<size_t>(bgr.rows) * bgr.cols * 3);
  unsigned char* out = rgb->data();
  for (int r = 0; r < bgr.rows; ++r)
    for (int c = 0; c < bgr.cols; ++c, out += 3) {
      const cv::Vec3b& px = bgr.at<cv::Vec3b>(r, c);
      out[0] = px[2], out[1] = px[1], out[2] = px[0];
    }
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const exotwin::RenderPluginTable* exotwin_render_plugin_v1() {
  static const exotwin::RenderPluginTable table = {exotwin::kRenderPluginAbi, sizeof(exotwin::RenderOptions),
                                                   sizeof(exotwin::OverlaySample), sizeof(std::string), &OpenVideo,
                                                   &RenderStill};
  return &table;
}
