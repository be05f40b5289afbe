// The entry point of the rendering plugin (render/render_plugin.h): one C symbol returning a table.
// Shared by the loader (render/render_plugin.cc) and the plugin (render/render_plugin_entry.cc).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "render/overlay_sample.h"
#include "render/render_options.h"
#include "render/video_sink.h"

struct mjModel_;

namespace exotwin {

// Raised whenever the table or a type that crosses the boundary changes meaning.
inline constexpr int kRenderPluginAbi = 3;  // 2: RenderOptions::legend; 3: render_still
inline constexpr char kRenderPluginEntry[] = "exotwin_render_plugin_v1";

struct RenderPluginTable {
  int abi;                                          // kRenderPluginAbi of the plugin's build
  std::size_t sizeof_options, sizeof_sample, sizeof_string;  // layout fingerprint of that build
  // A new VideoRenderer (owned by the caller, deleted through VideoSink's virtual destructor);
  // throws as its constructor does.
  VideoSink* (*open_video)(const mjModel_* m, const std::string& out_path, const RenderOptions& opt);
  // A still of `m` at the pose qpos (m->nq values): SceneRenderer's side view, no overlays, into *rgb
  // (opt.height rows top-down of opt.width RGB pixels); throws as SceneRenderer.
  void (*render_still)(const mjModel_* m, const double* qpos, const RenderOptions& opt, std::vector<unsigned char>* rgb);
};

// The table the loader expects from a plugin of its own build.
inline bool MatchesThisBuild(const RenderPluginTable& t) {
  return t.abi == kRenderPluginAbi && t.sizeof_options == sizeof(RenderOptions) &&
         t.sizeof_sample == sizeof(OverlaySample) && t.sizeof_string == sizeof(std::string);
}

}  // namespace exotwin

// The plugin's only exported symbol (named kRenderPluginEntry).
extern "C" const exotwin::RenderPluginTable* exotwin_render_plugin_v1();
