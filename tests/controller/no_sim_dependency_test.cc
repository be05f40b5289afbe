// The dependency rule of DESIGN.md, visible in the test suite: controller/ (the real controller
// code) never includes MuJoCo, OpenCV or simulation code. The build enforces it too (the configure-time
// layer check cmake/check_layers.cmake, and a shared library linked with --no-undefined).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace {

const std::regex kForbidden(R"(^\s*#\s*include\s*[<"](mujoco|opencv2?|sim/|hwsim/|render/|runner/))");

bool Forbidden(const std::string& line) { return std::regex_search(line, kForbidden); }

TEST(NoSimDependency, PatternCatchesForbiddenIncludes) {
  EXPECT_TRUE(Forbidden("#include <mujoco/mujoco.h>"));
  EXPECT_TRUE(Forbidden("#include <opencv2/core.hpp>"));
  EXPECT_TRUE(Forbidden("#include \"sim/plant.h\""));
  EXPECT_TRUE(Forbidden("  #  include \"hwsim/sensors.h\""));
  EXPECT_FALSE(Forbidden("#include \"controller/trajectory.h\""));
  EXPECT_FALSE(Forbidden("#include \"dsp/butterworth.h\""));
}

TEST(NoSimDependency, ControllerSourcesIncludeNoSimulationCode) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(EXOTWIN_SOURCE_DIR) / "controller";
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".h" && ext != ".cc" && ext != ".hpp" && ext != ".cpp") continue;
    ++files;
    std::ifstream in(entry.path());
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      EXPECT_FALSE(Forbidden(line)) << entry.path().string() << ":" << n << ": " << line;
    }
  }
  EXPECT_GE(files, 8);  // trajectory, pd_controller, state_estimator, safety_supervisor (.h + .cc)
}

}  // namespace
