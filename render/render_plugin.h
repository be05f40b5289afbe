// The rendering stack (OSMesa with LLVM's llvmpipe, OpenCV core/imgproc, FFmpeg with x264: over
// 100 shared libraries) is a plugin, loaded by the first OpenVideo of a process; commands that
// render nothing never map it (linking OpenCV's videoio into the executable had cost every command
// 256 libraries and 0.3 s).
//
// The plugin is the file kRenderPluginFile, looked for, in this order:
//   1. $EXOTWIN_RENDER_PLUGIN, when set (that file only: tests, relocated installs);
//   2. the folder of the running executable (/proc/self/exe): the build tree (build/app/);
//   3. <that folder>/../lib/exotwin/: an installed tree (<prefix>/bin/exotwin).
// It must come from the same build as the executable (the interface passes C++ types): its entry
// point checks kRenderPluginAbi and the sizes of the types that cross (render/render_plugin_abi.h).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "render/render_options.h"
#include "render/video_sink.h"

struct mjModel_;

namespace exotwin {

inline constexpr char kRenderPluginFile[] = "libexotwin_render_plugin.so";

// The paths OpenVideo tries, in order (see above).
std::vector<std::string> RenderPluginCandidates();

// Opens (once per process, never closed) the rendering plugin. Throws InputError naming every path
// tried when no plugin is found, and the file and the loader's message when it cannot be loaded
// (a missing dependency such as libOSMesa) or belongs to another build.
void LoadRenderPlugin();

// A video of model `m` (copied) written to `out_path` (MP4): render/video_renderer.h's VideoRenderer
// behind the plugin. Loads the plugin first (LoadRenderPlugin's errors); then throws as the
// VideoRenderer constructor does (InputError for a bad path, fps or size; std::runtime_error if
// OpenGL or the encoder cannot be set up).
std::unique_ptr<VideoSink> OpenVideo(const mjModel_* m, const std::string& out_path, const RenderOptions& opt);

// A still of model `m` at the pose qpos (m->nq values, as mjData::qpos): the videos' side view without
// overlays, opt.height rows top-down of opt.width RGB pixels (3 bytes each). Loads the plugin first
// (LoadRenderPlugin's errors); std::invalid_argument for a bad size, std::runtime_error if OpenGL
// cannot be set up.
std::vector<unsigned char> RenderStill(const mjModel_* m, const double* qpos, const RenderOptions& opt);

}  // namespace exotwin
