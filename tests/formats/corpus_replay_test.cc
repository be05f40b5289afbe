// Smoke run of the fuzz targets in the normal test suite (works without clang): every file of the
// fuzz corpora (fuzz/corpus/fuzz_csv, fuzz/corpus/fuzz_model_yaml: seeds and the crashers the
// fuzzers found) goes through the same contract as the fuzzers (fuzz/harness.h): it either parses or
// throws InputError; any other exception is a failure (a crash fails the whole test binary).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fuzz/harness.h"

namespace exotwin {
namespace {

std::vector<std::string> CorpusFiles(const std::string& target) {
  std::vector<std::string> files;
  const std::filesystem::path dir = std::filesystem::path(EXOTWIN_SOURCE_DIR) / "fuzz" / "corpus" / target;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(CorpusReplay, MeasuredCsvParsesOrThrowsInputError) {
  const auto files = CorpusFiles("fuzz_csv");
  ASSERT_GE(files.size(), 10u);
  int parsed = 0;
  for (const auto& f : files) {
    try {
      parsed += fuzz::MeasuredCsvFile(f);
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);  // the valid seeds
}

// The seeds say what they are: valid_* parse (BOM, quotes, CRLF, a trailing comma included),
// invalid_* are rejected.
TEST(CorpusReplay, MeasuredCsvSeedsParseAsTheirNamesSay) {
  for (const auto& f : CorpusFiles("fuzz_csv")) {
    const std::string name = std::filesystem::path(f).filename().string();
    if (name.rfind("valid_", 0) == 0) {
      EXPECT_TRUE(fuzz::MeasuredCsvFile(f)) << name;
    } else if (name.rfind("invalid_", 0) == 0) {
      EXPECT_FALSE(fuzz::MeasuredCsvFile(f)) << name;
    }
  }
}

TEST(CorpusReplay, ModelYamlParsesOrThrowsInputError) {
  const auto files = CorpusFiles("fuzz_model_yaml");
  ASSERT_GE(files.size(), 8u);
  int parsed = 0;
  for (const auto& f : files) {
    try {
      parsed += fuzz::ModelYamlText(Slurp(f));
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);
}

}  // namespace
}  // namespace exotwin
