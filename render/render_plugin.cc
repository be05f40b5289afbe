#include "render/render_plugin.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "core/data_dir.h"
#include "core/error.h"
#include "core/output_path.h"
#include "render/render_plugin_abi.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

const RenderPluginTable* g_table = nullptr;  // set once by LoadRenderPlugin, under g_once
std::once_flag g_once;

// Loads `path` (RTLD_LOCAL: its libraries stay out of the process's global symbol scope) and returns
// its table; throws InputError naming the file.
const RenderPluginTable* Open(const std::string& path) {
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) throw InputError("render: cannot load the rendering plugin " + path + ": " + dlerror());
  using Entry = const RenderPluginTable* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(h, kRenderPluginEntry));
  const RenderPluginTable* t = entry ? entry() : nullptr;
  if (!t || !MatchesThisBuild(*t))
    throw InputError("render: " + path + " is not a rendering plugin of this build of exotwin (entry " +
                     kRenderPluginEntry + " missing or of another version); rebuild or reinstall both");
  return t;  // the handle is never closed: videos hold code of the plugin
}

}  // namespace

std::vector<std::string> RenderPluginCandidates() {
  if (const char* env = std::getenv("EXOTWIN_RENDER_PLUGIN"); env && *env) return {env};
  const fs::path exe = ExecutablePath();
  if (exe.empty()) return {};
  const fs::path dir = exe.parent_path();
  return {(dir / kRenderPluginFile).string(),
          (dir.parent_path() / "lib" / "exotwin" / kRenderPluginFile).string()};
}

void LoadRenderPlugin() {
  std::call_once(g_once, [] {
    const std::vector<std::string> tried = RenderPluginCandidates();
    for (const std::string& p : tried) {
      std::error_code ec;
      if (fs::exists(p, ec)) {
        g_table = Open(p);
        return;
      }
    }
    std::string list;
    for (const std::string& p : tried) list += (list.empty() ? "" : ", ") + p;
    throw InputError(std::string("render: the rendering plugin ") + kRenderPluginFile +
                     " was not found (looked for " + (list.empty() ? "nothing: /proc/self/exe unreadable" : list) +
                     "); it is built next to the exotwin executable and installed in <prefix>/lib/exotwin/");
  });
}

std::unique_ptr<VideoSink> OpenVideo(const mjModel_* m, const std::string& out_path, const RenderOptions& opt) {
  LoadRenderPlugin();
  CreateParentFolders(out_path);
  return std::unique_ptr<VideoSink>(g_table->open_video(m, out_path, opt));
}

std::vector<unsigned char> RenderStill(const mjModel_* m, const double* qpos, const RenderOptions& opt) {
  LoadRenderPlugin();
  std::vector<unsigned char> rgb;
  g_table->render_still(m, qpos, opt, &rgb);
  return rgb;
}

}  // namespace exotwin
