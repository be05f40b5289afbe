// The corpus of a fuzz target as the corpus-replay tests read it (tests/*/corpus_replay_test.cc,
// tests/protocol/candump_corpus_replay_test.cc): its files, sorted, and their bytes.
#pragma once
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace exotwin::fuzz {

// The files of fuzz/corpus/<target> under the source folder `source_dir`, sorted by name.
inline std::vector<std::string> CorpusFiles(const std::string& source_dir, const std::string& target) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(source_dir) / "fuzz" / "corpus" / target))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

// The bytes of `path`.
inline std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace exotwin::fuzz
