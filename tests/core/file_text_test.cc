// ReadTextFile: the content byte for byte, and an InputError naming the path for a missing file, a
// directory and a NUL byte.
#include "core/file_text.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

std::string MessageOf(const std::string& path, const std::string& what, const std::string& expected) {
  try {
    ReadTextFile(path, what, expected);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FileText, ReadsTheWholeFileAsStored) {
  const testing::ScopedTempDir tmp("file_text");
  const std::string& dir = tmp.path();
  const std::string text = "a,b\r\n1,2\n\xc3\xa9 no final newline";
  std::ofstream(dir + "/t.csv", std::ios::binary) << text;
  EXPECT_EQ(ReadTextFile(dir + "/t.csv", "", "a text CSV file"), text);
  std::ofstream(dir + "/empty.txt", std::ios::binary);
  EXPECT_EQ(ReadTextFile(dir + "/empty.txt", "", "a text file"), "");
}

TEST(FileText, MissingFileDirectoryAndNulAreInputErrorsNamingThePath) {
  const testing::ScopedTempDir tmp("file_text");
  const std::string& dir = tmp.path();
  EXPECT_EQ(MessageOf(dir + "/none.yaml", "model", "a YAML text file"),
            dir + "/none.yaml: cannot open model file (No such file or directory)");
  EXPECT_EQ(MessageOf(dir + "/none.csv", "", "a text CSV file"),
            dir + "/none.csv: cannot open file (No such file or directory)");
  EXPECT_EQ(MessageOf(dir, "scenario", "a YAML text file"), dir + ": cannot open scenario file (is a directory)");
  std::ofstream(dir + "/nul.yaml", std::ios::binary) << std::string("a: 1\n\0b: 2\n", 11);
  EXPECT_EQ(MessageOf(dir + "/nul.yaml", "model", "a YAML text file"),
            dir + "/nul.yaml: binary data (NUL byte), expected a YAML text file");
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// TextFileChunks: chunks concatenate to the file; the rest drained with its newlines counted.
TEST(TextFileChunks, ChunksAndDrainCoverTheFile) {
  const testing::ScopedTempDir tmp("chunks");
  const std::string path = tmp.path() + "/c.txt";
  std::string text;
  for (int i = 0; i < 5000; ++i) text += "line " + std::to_string(i) + "\n";
  std::ofstream(path, std::ios::binary) << text << "tail";
  TextFileChunks in(path, "", "a text file");
  EXPECT_EQ(in.size(), text.size() + 4);
  char buf[1000];
  ASSERT_EQ(in.Read(buf, sizeof(buf)), sizeof(buf));
  EXPECT_EQ(std::string(buf, sizeof(buf)), text.substr(0, sizeof(buf)));
  bool ends_with_newline = true;
  const size_t rest = in.DrainCountingNewlines(&ends_with_newline);
  EXPECT_EQ(rest, 5000u - static_cast<size_t>(std::count(buf, buf + sizeof(buf), '\n')));
  EXPECT_FALSE(ends_with_newline);
  EXPECT_EQ(in.Read(buf, sizeof(buf)), 0u);
  EXPECT_THROW(TextFileChunks(tmp.path(), "", "a text file"), InputError);
}

}  // namespace
}  // namespace exotwin
