// Smoke run of the candump fuzz target in the normal test suite (works without clang): every file of
// fuzz/corpus/fuzz_candump (seeds and the crashers the fuzzer found) either reads or throws
// InputError (fuzz/harness_candump.h); any other exception is a failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "fuzz/harness_candump.h"

namespace exotwin {
namespace {

TEST(CorpusReplay, CandumpReadsOrThrowsInputError) {
  const std::filesystem::path dir =
      std::filesystem::path(EXOTWIN_SOURCE_DIR) / "fuzz" / "corpus" / "fuzz_candump";
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 8u);
  int read = 0;
  for (const auto& f : files) {
    try {
      read += fuzz::CandumpFile(f);
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(read, 3);
}

}  // namespace
}  // namespace exotwin
