#include "core/data_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

// Sets (or unsets) EXOTWIN_DATA_DIR for one test and restores the caller's value.
class ScopedDataDirEnv {
 public:
  explicit ScopedDataDirEnv(const std::optional<std::string>& value) {
    if (const char* old = std::getenv("EXOTWIN_DATA_DIR")) old_ = old;
    if (value) ::setenv("EXOTWIN_DATA_DIR", value->c_str(), 1);
    else ::unsetenv("EXOTWIN_DATA_DIR");
  }
  ~ScopedDataDirEnv() {
    if (old_) ::setenv("EXOTWIN_DATA_DIR", old_->c_str(), 1);
    else ::unsetenv("EXOTWIN_DATA_DIR");
  }

 private:
  std::optional<std::string> old_;
};

std::string ExecutableShareDir() {
  return (fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "share" / "exotwin").string();
}

TEST(DataDir, WithoutTheVariableIsShareExotwinNextToTheExecutablesFolder) {
  ScopedDataDirEnv env(std::nullopt);
  EXPECT_EQ(DataDir(), ExecutableShareDir());
  // The build tree mirrors the installed layout: the shipped folders are there.
  for (const char* f : {"mjcf/leg_exowheel.xml", "data/WinterTableA1.txt", "scenarios/gait_2kmh.yaml",
                        "scenarios/baselines", "examples/S1.yaml"})
    EXPECT_TRUE(fs::exists(DataPath(f))) << DataPath(f);
}

TEST(DataDir, AnEmptyVariableCountsAsUnset) {
  ScopedDataDirEnv env(std::string(""));
  EXPECT_EQ(DataDir(), ExecutableShareDir());
}

TEST(DataDir, TheVariableOverridesTheExecutablesLocation) {
  testing::ScopedTempDir tmp("data_dir");
  ScopedDataDirEnv env(tmp.path() + "/");
  EXPECT_EQ(DataDir(), tmp.path());
  EXPECT_EQ(DataPath("mjcf/x.xml"), tmp.path() + "/mjcf/x.xml");
}

TEST(DataDir, AMissingFolderIsAnInputErrorNamingWhatWasLookedFor) {
  testing::ScopedTempDir tmp("data_dir");
  const std::string missing = tmp.path() + "/no_such_folder";
  ScopedDataDirEnv env(missing);
  try {
    DataPath("mjcf/leg_exowheel.xml");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("looked for " + missing), std::string::npos) << msg;
    EXPECT_NE(msg.find("EXOTWIN_DATA_DIR"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace exotwin
