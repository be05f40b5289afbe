// Smoke run of the candump fuzz target in the normal test suite (works without clang): every file of
// fuzz/corpus/fuzz_candump (seeds and the crashers the fuzzer found) either reads or throws
// InputError (fuzz/harness_candump.h); any other exception is a failure.
#include <gtest/gtest.h>


#include "fuzz/corpus_files.h"
#include "fuzz/harness_candump.h"

namespace exotwin {
namespace {

TEST(CorpusReplay, CandumpReadsOrThrowsInputError) {
  const std::vector<std::string> files = fuzz::CorpusFiles(EXOTWIN_SOURCE_DIR, "fuzz_candump");
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
