// The rendering stack is loaded only by the commands that render (render/render_plugin.h): the
// dynamic loader's own record (LD_DEBUG=files, every object mapped, also by dlopen) shows no
// libOSMesa and no libopencv for `--help` and a `run` without video, and shows them (and FFmpeg's
// libavcodec) for `render`.
// A copy of the executable without the plugin runs every other command and exits 2 on a render,
// naming the files looked for; with the plugin in <prefix>/lib/exotwin/ it renders.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "render/render_plugin.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;
using testing::RunExotwin;
using testing::WriteText;

const char kScenario[] =
    "name: plugin\ndevice: exowheel\nsubject: {preset: S1}\nprotocol: {trajectory: hold, duration: 0.2, ramp: 0}\n";

// `exotwin <args>` with the loader's file log merged into the output.
testing::RunResult RunLogged(const std::string& args) {
  setenv("LD_DEBUG", "files", 1);
  const testing::RunResult r = RunExotwin(args);
  unsetenv("LD_DEBUG");
  return r;
}

bool Maps(const std::string& log, const std::string& lib) { return log.find(lib) != std::string::npos; }

class RenderPluginCli : public ::testing::Test {
 protected:
  void SetUp() override { WriteText(dir_ + "/s.yaml", kScenario); }
  const testing::ScopedTempDir tmp_{"render_plugin_cli"};
  const std::string dir_ = tmp_.path();
};

TEST_F(RenderPluginCli, HelpMapsNeitherOsMesaNorOpenCv) {
  const auto r = RunLogged("--help");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(Maps(r.output, "libmujoco")) << "LD_DEBUG=files logged nothing:\n" << r.output;
  EXPECT_FALSE(Maps(r.output, "libOSMesa")) << r.output;
  EXPECT_FALSE(Maps(r.output, "libopencv")) << r.output;
  EXPECT_FALSE(Maps(r.output, kRenderPluginFile)) << r.output;
}

TEST_F(RenderPluginCli, RunWithoutVideoMapsNeitherOsMesaNorOpenCv) {
  const auto r = RunLogged("run " + dir_ + "/s.yaml --out " + dir_ + "/out");
  ASSERT_LE(r.exit_code, 1) << r.output;
  ASSERT_TRUE(fs::exists(dir_ + "/out/result.json")) << r.output;
  EXPECT_FALSE(Maps(r.output, "libOSMesa")) << r.output;
  EXPECT_FALSE(Maps(r.output, "libopencv")) << r.output;
}

TEST_F(RenderPluginCli, RenderMapsThePluginOsMesaAndOpenCv) {
  const auto r = RunLogged("render " + dir_ + "/s.yaml -o " + dir_ + "/v.mp4 --out " + dir_ + "/out");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir_ + "/v.mp4"));
  EXPECT_TRUE(Maps(r.output, kRenderPluginFile));
  EXPECT_TRUE(Maps(r.output, "libOSMesa"));
  EXPECT_TRUE(Maps(r.output, "libopencv_imgproc"));
  EXPECT_TRUE(Maps(r.output, "libavcodec"));
}

TEST_F(RenderPluginCli, WithoutThePluginOnlyRenderingFailsNamingTheFiles) {
  fs::create_directories(dir_ + "/prefix/bin");
  const std::string exe = dir_ + "/prefix/bin/exotwin";
  fs::copy_file(testing::ExotwinBin(), exe);  // its RUNPATH still finds the build's libraries
  const std::string built = testing::ExotwinBin();
  // The data folder of the installed layout (<prefix>/share/exotwin, core/data_dir.h): the build's.
  fs::create_directories(dir_ + "/prefix/share");
  fs::create_directory_symlink(fs::canonical(fs::path(built).parent_path().parent_path() / "share" / "exotwin"),
                               dir_ + "/prefix/share/exotwin");
  setenv("EXOTWIN_BIN", exe.c_str(), 1);  // RunExotwin runs the copy
  const auto help = RunExotwin("--help");
  const auto plain = RunExotwin("run " + dir_ + "/s.yaml --out " + dir_ + "/out");
  const auto render = RunExotwin("render " + dir_ + "/s.yaml -o " + dir_ + "/v.mp4 --out " + dir_ + "/out_r");
  // Installed layout: <prefix>/bin/exotwin finds <prefix>/lib/exotwin/<plugin>.
  fs::create_directories(dir_ + "/prefix/lib/exotwin");
  fs::copy_file(fs::path(built).parent_path() / kRenderPluginFile, dir_ + "/prefix/lib/exotwin/" + kRenderPluginFile);
  const auto installed = RunExotwin("render " + dir_ + "/s.yaml -o " + dir_ + "/w.mp4 --out " + dir_ + "/out_w");
  setenv("EXOTWIN_BIN", built.c_str(), 1);

  EXPECT_EQ(help.exit_code, 0) << help.output;
  EXPECT_LE(plain.exit_code, 1) << plain.output;
  EXPECT_TRUE(fs::exists(dir_ + "/out/result.json")) << plain.output;
  EXPECT_EQ(render.exit_code, 2) << render.output;
  for (const std::string& f : {dir_ + "/prefix/bin/" + kRenderPluginFile,
                               dir_ + "/prefix/lib/exotwin/" + kRenderPluginFile})
    EXPECT_NE(render.output.find(f), std::string::npos) << f << " not named in:\n" << render.output;
  EXPECT_FALSE(fs::exists(dir_ + "/v.mp4"));
  EXPECT_EQ(installed.exit_code, 0) << installed.output;
  EXPECT_TRUE(fs::exists(dir_ + "/w.mp4"));
}

}  // namespace
}  // namespace exotwin
