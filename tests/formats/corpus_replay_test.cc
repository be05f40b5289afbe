// Smoke run of the fuzz targets in the normal test suite (works without clang): every file of the
// fuzz corpora (fuzz/corpus/fuzz_csv, fuzz_model_yaml, fuzz_column_map, fuzz_opensim_storage, fuzz_mcap: seeds and
// the crashers the fuzzers found) goes through the same contract as the fuzzers (fuzz/harness.h): it
// either parses or throws InputError, and what parses is written and read back; any other exception
// is a failure (a crash fails the whole test binary).
#include <gtest/gtest.h>

#include <filesystem>

#include "fuzz/corpus_files.h"
#include "fuzz/harness.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

std::vector<std::string> CorpusFiles(const std::string& target) { return fuzz::CorpusFiles(EXOTWIN_SOURCE_DIR, target); }

TEST(CorpusReplay, MeasuredCsvParsesOrThrowsInputError) {
  const testing::ScopedTempDir tmp("corpus_csv");
  const auto files = CorpusFiles("fuzz_csv");
  ASSERT_GE(files.size(), 10u);
  int parsed = 0;
  for (const auto& f : files) {
    try {
      parsed += fuzz::MeasuredCsvFile(f, tmp.path());
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);  // the valid seeds
}

// The seeds say what they are: valid_* parse (BOM, quotes, CRLF, a trailing comma included),
// invalid_* are rejected.
TEST(CorpusReplay, MeasuredCsvSeedsParseAsTheirNamesSay) {
  const testing::ScopedTempDir tmp("corpus_csv");
  for (const auto& f : CorpusFiles("fuzz_csv")) {
    const std::string name = std::filesystem::path(f).filename().string();
    if (name.rfind("valid_", 0) == 0) {
      EXPECT_TRUE(fuzz::MeasuredCsvFile(f, tmp.path())) << name;
    } else if (name.rfind("invalid_", 0) == 0) {
      EXPECT_FALSE(fuzz::MeasuredCsvFile(f, tmp.path())) << name;
    }
  }
}

TEST(CorpusReplay, ModelYamlParsesOrThrowsInputError) {
  const auto files = CorpusFiles("fuzz_model_yaml");
  ASSERT_GE(files.size(), 8u);
  int parsed = 0;
  for (const auto& f : files) {
    try {
      parsed += fuzz::ModelYamlText(fuzz::FileBytes(f));
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GE(parsed, 3);
}

// Every corpus file of `target` through `harness` (file text, scratch folder); valid_* must parse,
// invalid_* must not.
template <class Harness>
void ReplayTextCorpus(const std::string& target, Harness harness) {
  const testing::ScopedTempDir tmp(target);
  const auto files = CorpusFiles(target);
  ASSERT_GE(files.size(), 5u);
  for (const auto& f : files) {
    const std::string name = std::filesystem::path(f).filename().string();
    try {
      const bool parsed = harness(fuzz::FileBytes(f), tmp.path());
      if (name.rfind("valid_", 0) == 0) {
        EXPECT_TRUE(parsed) << name;
      }
      if (name.rfind("invalid_", 0) == 0 || name.rfind("crash_", 0) == 0) {
        EXPECT_FALSE(parsed) << name;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
}

TEST(CorpusReplay, ColumnMapsApplyOrThrowInputError) { ReplayTextCorpus("fuzz_column_map", fuzz::ColumnMapText); }

TEST(CorpusReplay, OpenSimStorageParsesOrThrowsInputError) { ReplayTextCorpus("fuzz_opensim_storage", fuzz::StorageText); }

TEST(CorpusReplay, McapBagsParseOrThrowInputError) { ReplayTextCorpus("fuzz_mcap", fuzz::McapBytes); }

}  // namespace
}  // namespace exotwin
