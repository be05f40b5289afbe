// Smoke run of the scenario fuzz target in the normal test suite (works without clang): every file of
// fuzz/corpus/fuzz_scenario_yaml (seeds and the crashers the fuzzer found) either parses or throws
// InputError; any other exception is a failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

TEST(CorpusReplay, ScenarioYamlParsesOrThrowsInputError) {
  const std::filesystem::path dir =
      std::filesystem::path(EXOTWIN_SOURCE_DIR) / "fuzz" / "corpus" / "fuzz_scenario_yaml";
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 8u);
  int parsed = 0;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    try {
      ParseScenarioYaml(ss.str(), f);
      ++parsed;
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);
}

}  // namespace
}  // namespace exotwin
