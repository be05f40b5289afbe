// The rendering plugin's entry point (render/render_plugin_abi.h): the only symbol the module
// exports (render/CMakeLists.txt hides the rest).
#include "render/render_plugin_abi.h"
#include "render/video_renderer.h"

namespace {

exotwin::VideoSink* OpenVideo(const mjModel_* m, const std::string& out_path, const exotwin::RenderOptions& opt) {
  return new exotwin::VideoRenderer(m, out_path, opt);
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const exotwin::RenderPluginTable* exotwin_render_plugin_v1() {
  static const exotwin::RenderPluginTable table = {exotwin::kRenderPluginAbi, sizeof(exotwin::RenderOptions),
                                                   sizeof(exotwin::OverlaySample), sizeof(std::string), &OpenVideo};
  return &table;
}
