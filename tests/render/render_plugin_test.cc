// render/render_plugin.h: where the plugin is looked for, a video opened through it, and the error
// that names the file when it is missing. The plugin is the build's (next to $EXOTWIN_BIN).
#include "render/render_plugin.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "sim/plant.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

std::string BuiltPlugin() {
  const char* bin = std::getenv("EXOTWIN_BIN");
  const fs::path exe = bin ? fs::path(bin) : fs::path(EXOTWIN_SOURCE_DIR) / "build/app/exotwin";
  return (exe.parent_path() / kRenderPluginFile).string();
}

// Sets or clears an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    if (value) setenv(name, value, 1);
    else unsetenv(name);
  }
  ~ScopedEnv() {
    if (had_) setenv(name_, old_.c_str(), 1);
    else unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

TEST(RenderPlugin, LooksNextToTheExecutableThenInLibExotwin) {
  const ScopedEnv env("EXOTWIN_RENDER_PLUGIN", nullptr);
  const fs::path dir = fs::read_symlink("/proc/self/exe").parent_path();
  const std::vector<std::string> c = RenderPluginCandidates();
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], (dir / "libexotwin_render_plugin.so").string());
  EXPECT_EQ(c[1], (dir.parent_path() / "lib/exotwin/libexotwin_render_plugin.so").string());
}

TEST(RenderPlugin, EnvironmentNamesTheOnlyFile) {
  const ScopedEnv env("EXOTWIN_RENDER_PLUGIN", "/opt/x/plugin.so");
  EXPECT_EQ(RenderPluginCandidates(), std::vector<std::string>{"/opt/x/plugin.so"});
}

// LoadRenderPlugin with $EXOTWIN_RENDER_PLUGIN = `path`, in a child process (the plugin state is per
// process, and a successful load is kept): exits 2 with the InputError's message on stderr.
void LoadInChild(const char* path) {
  setenv("EXOTWIN_RENDER_PLUGIN", path, 1);
  try {
    LoadRenderPlugin();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    std::exit(2);
  }
  std::exit(0);
}

TEST(RenderPluginDeathTest, MissingPluginThrowsInputErrorNamingTheFile) {
  EXPECT_EXIT(LoadInChild("/no/such/dir/libexotwin_render_plugin.so"), ::testing::ExitedWithCode(2),
              "was not found \\(looked for /no/such/dir/libexotwin_render_plugin.so\\)");
}

TEST(RenderPluginDeathTest, ForeignLibraryIsRefusedNamingIt) {
  // A shared library without the entry point (libm) is not taken for the plugin.
  EXPECT_EXIT(LoadInChild("/lib/x86_64-linux-gnu/libm.so.6"), ::testing::ExitedWithCode(2),
              "libm.so.6 is not a rendering plugin of this build");
}

TEST(RenderPlugin, OpensAVideoThroughThePlugin) {
  const std::string plugin = BuiltPlugin();
  ASSERT_TRUE(fs::exists(plugin)) << plugin;
  const ScopedEnv env("EXOTWIN_RENDER_PLUGIN", plugin.c_str());
  const testing::ScopedTempDir tmp("render_plugin");
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  RenderOptions opt;
  opt.width = 160, opt.height = 120;
  std::unique_ptr<VideoSink> v = OpenVideo(plant.model(), tmp.File("p.mp4"), opt);
  for (int i = 0; i < 1000; ++i) {
    OverlaySample s;
    s.t = i * 1e-3;
    s.q_hip = 0.5 * std::sin(s.t);
    s.q_knee = -0.5;
    v->AddSample(s);
  }
  v->Finish(1.0);
  EXPECT_EQ(v->frames(), 30);
  EXPECT_EQ(v->stats().frames, 30);
  EXPECT_TRUE(fs::exists(tmp.File("p.mp4")));
  // Errors of the renderer cross the plugin boundary with their type (a missing parent folder is
  // created, DESIGN.md "Command line"; one under a regular file cannot be).
  EXPECT_THROW(OpenVideo(plant.model(), tmp.File("p.mp4/x.mp4"), opt), InputError);
}

}  // namespace
}  // namespace exotwin
