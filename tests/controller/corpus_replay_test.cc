// Smoke run of the controller-file fuzz target in the normal test suite (works without clang): every
// file of fuzz/corpus/fuzz_controller_yaml goes through the fuzzer's contract
// (fuzz/harness_controller.h): it parses and reads back as written, or throws InputError; valid_*
// parse, invalid_* are refused.
#include <gtest/gtest.h>

#include <filesystem>

#include "fuzz/corpus_files.h"
#include "fuzz/harness_controller.h"

namespace exotwin {
namespace {

TEST(CorpusReplay, ControllerFileParsesOrThrowsInputError) {
  const std::vector<std::string> files = fuzz::CorpusFiles(EXOTWIN_SOURCE_DIR, "fuzz_controller_yaml");
  ASSERT_GE(files.size(), 5u);
  int parsed = 0;
  for (const auto& f : files) {
    const std::string name = std::filesystem::path(f).filename().string();
    try {
      const bool ok = fuzz::ControllerText(fuzz::FileBytes(f));
      parsed += ok;
      if (name.rfind("valid_", 0) == 0) EXPECT_TRUE(ok) << name;
      if (name.rfind("invalid_", 0) == 0) EXPECT_FALSE(ok) << name;
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 2);
}

}  // namespace
}  // namespace exotwin
