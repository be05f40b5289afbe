// CSV tables: a streamed log cut anywhere by a killed run reads back as its complete rows; the same
// cut in a file without the stream marker is an error; a hand-written file may omit the last newline.
#include "tests/temp_dir.h"
#include "analysis/csv_table.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/error.h"

namespace exotwin {
namespace {

std::string TempPath(const std::string& name) {
  static const testing::ScopedTempDir tmp("csv");  // the suite's folder, removed at exit
  const std::string& dir = tmp.path();
  return dir + "/" + name;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void Spit(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// Every byte at which the kernel could cut the last write of a killed run (Linux cuts a regular-file
// write(2) between pages on SIGKILL, so any offset inside a line is possible).
TEST(CsvStreamWriter, ACutAnywhereInTheLastRowKeepsEveryCompleteRow) {
  const std::string path = TempPath("stream.csv");
  {
    CsvStreamWriter w(path, {"t", "a", "b"}, {"a comment"}, 2);
    for (int i = 0; i < 5; ++i) {
      const double row[3] = {0.001 * i, 1.0 / 3 + i, -2.5e-7 * i};
      w.Row(row, 3);
    }
  }
  const std::string full = Slurp(path);
  ASSERT_EQ(full.rfind(kStreamMarker, 0), 0u);
  EXPECT_EQ(ReadCsv(path).rows(), 5u);
  EXPECT_EQ(ReadCsv(path).dropped_cut_line, 0);
  const size_t last_row_begin = full.rfind('\n', full.size() - 2) + 1;
  for (size_t cut = last_row_begin + 1; cut < full.size(); ++cut) {
    Spit(path, full.substr(0, cut));
    const CsvTable t = ReadCsv(path);
    EXPECT_EQ(t.rows(), 4u) << "cut at byte " << cut;
    EXPECT_EQ(t.dropped_cut_line, 8) << "marker, comment, header, 4 rows, then the cut line";
    EXPECT_DOUBLE_EQ(t.columns[1][3], 1.0 / 3 + 3);  // the complete rows are intact, to the bit
  }
  // A cut exactly after a newline loses nothing that was complete.
  Spit(path, full.substr(0, last_row_begin));
  EXPECT_EQ(ReadCsv(path).rows(), 4u);
  EXPECT_EQ(ReadCsv(path).dropped_cut_line, 0);
  std::filesystem::remove(path);
}

TEST(ReadCsv, ACutRowWithoutTheStreamMarkerIsAnError) {
  const std::string path = TempPath("plain.csv");
  Spit(path, "t,a,b\n0,1,2\n0.1,1.");
  try {
    ReadCsv(path);
    FAIL() << "a short last row of a plain CSV must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: expected 3 fields"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(ReadCsv, AHandWrittenFileMayOmitTheLastNewline) {
  const std::string path = TempPath("hand.csv");
  Spit(path, "t,a\n0,1\n0.1,2");
  const CsvTable t = ReadCsv(path);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.columns[1][1], 2.0);
  EXPECT_EQ(t.dropped_cut_line, 0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace exotwin
