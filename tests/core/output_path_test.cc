// Output folders: created with their missing parents; a file in the way, or a folder that cannot be
// created, is an InputError naming the path.
#include "core/output_path.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

TEST(OutputPath, CreatesMissingParentsAndNamesWhatIsInTheWay) {
  const testing::ScopedTempDir tmp("output_path");
  const std::string d = tmp.path() + "/a/b/c";
  CreateOutputFolder(d);
  EXPECT_TRUE(std::filesystem::is_directory(d));
  CreateOutputFolder(d);  // already there
  CreateParentFolders(tmp.path() + "/x/y/file.csv");
  EXPECT_TRUE(std::filesystem::is_directory(tmp.path() + "/x/y"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/x/y/file.csv"));
  CreateParentFolders("bare_name.csv");  // the current folder: nothing to create
  std::ofstream(tmp.path() + "/f") << "x";
  try {
    CreateOutputFolder(tmp.path() + "/f");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), tmp.path() + "/f: exists and is not a folder, expected an output folder (created when missing)");
  }
  try {
    CreateParentFolders(tmp.path() + "/f/g/out.csv");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(tmp.path() + "/f/g: cannot create the output folder (", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace exotwin
