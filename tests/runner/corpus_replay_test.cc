// Smoke run of the scenario fuzz target in the normal test suite (works without clang): every file of
// fuzz/corpus/fuzz_scenario_yaml (seeds and the crashers the fuzzer found) goes through the fuzzer's
// contract (fuzz/harness_scenario.h): it either parses or throws InputError, and a scenario that parses
// ends as `run` ends it (result.json valid); valid_* parse, invalid_* and crash_* are refused.
#include <gtest/gtest.h>

#include <filesystem>

#include "formats/csv_table.h"
#include "fuzz/corpus_files.h"
#include "fuzz/harness_scenario.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

TEST(CorpusReplay, ScenarioYamlParsesOrThrowsInputError) {
  const std::vector<std::string> files = fuzz::CorpusFiles(EXOTWIN_SOURCE_DIR, "fuzz_scenario_yaml");
  ASSERT_GE(files.size(), 8u);
  const testing::ScopedTempDir tmp("corpus_scenario");
  WriteFileAtomic(tmp.File("plant.yaml"), fuzz::kPlantFile);
  int parsed = 0;
  for (const auto& f : files) {
    const std::string name = std::filesystem::path(f).filename().string();
    try {
      const bool ok = fuzz::ScenarioText(fuzz::FileBytes(f), tmp.path());
      parsed += ok;
      if (name.rfind("valid_", 0) == 0) {
        EXPECT_TRUE(ok) << name;
      }
      if (name.rfind("invalid_", 0) == 0 || name.rfind("crash_", 0) == 0) {
        EXPECT_FALSE(ok) << name;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);
}

}  // namespace
}  // namespace exotwin
