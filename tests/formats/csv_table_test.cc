// CSV tables: a streamed log cut anywhere by a killed run reads back as its complete rows; the same
// cut in a file without the stream marker is an error; a hand-written file may omit the last newline.
// Files as spreadsheets and lab software write them (issue 21): a byte-order mark, CRLF line ends,
// RFC 4180 quotes and a trailing comma on every line read as the plain file does, to the bit; a
// semicolon-separated file, a folder, broken quotes get a message naming the place and the fix.
#include "tests/temp_dir.h"
#include "formats/csv_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>
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

// The writer thread's text is WriteCsv's (AppendNumber), row for row and in order across many blocks;
// Flush returns once every row so far is in the file; a missing value is written as 0.
TEST(CsvStreamWriter, WritesWhatWriteCsvWritesAndFlushMakesRowsVisible) {
  const std::string path = TempPath("stream_blocks.csv"), plain = TempPath("plain_blocks.csv");
  std::vector<double> t, a, b;
  for (int i = 0; i < 1037; ++i) t.push_back(1e-3 * i), a.push_back(std::sin(0.37 * i) / 3), b.push_back(-1e-9 * i * i);
  {
    CsvStreamWriter w(path, {"t", "a", "b"}, {}, 64);
    for (size_t i = 0; i < t.size(); ++i) {
      const double row[3] = {t[i], a[i], b[i]};
      w.Row(row, 3);
      if (i == 500) {
        w.Flush();
        EXPECT_EQ(ReadCsv(path).rows(), 501u);  // every row appended so far, none waiting in a block
      }
    }
    const double short_row[1] = {2.0};
    w.Row(short_row, 1);
    EXPECT_EQ(w.rows(), t.size() + 1);
  }
  t.push_back(2.0), a.push_back(0.0), b.push_back(0.0);
  WriteCsv(plain, {"t", "a", "b"}, {&t, &a, &b});
  const std::string streamed = Slurp(path), written = Slurp(plain);
  const size_t body = streamed.find("t,a,b\n");
  ASSERT_NE(body, std::string::npos);
  EXPECT_TRUE(streamed.substr(body) == written.substr(written.find("t,a,b\n")));
  std::filesystem::remove(path);
  std::filesystem::remove(plain);
}

// A write error is reported as an InputError naming the file (here: /dev/full, no space left).
TEST(CsvStreamWriter, AWriteErrorIsAnInputErrorNamingTheFile) {
  try {
    CsvStreamWriter w("/dev/full", {"t"}, {}, 4);
    FAIL() << "the header cannot be written to /dev/full";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: write failed"), std::string::npos) << e.what();
  }
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

// The message of the InputError `f` throws ("" if none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string ReadError(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  Spit(path, text);
  return ErrorOf([&] { ReadCsv(path); });
}

CsvTable ReadText(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  Spit(path, text);
  return ReadCsv(path);
}

void ExpectSameTable(const CsvTable& a, const CsvTable& b, const std::string& what) {
  EXPECT_EQ(a.names, b.names) << what;
  ASSERT_EQ(a.columns.size(), b.columns.size()) << what;
  for (size_t c = 0; c < a.columns.size(); ++c) {
    ASSERT_EQ(a.columns[c].size(), b.columns[c].size()) << what;
    // Bit for bit (NaN included).
    EXPECT_EQ(0, std::memcmp(a.columns[c].data(), b.columns[c].data(), a.columns[c].size() * sizeof(double)))
        << what << ", column " << a.names[c];
  }
  EXPECT_EQ(a.line_of_row, b.line_of_row) << what;
}

const char kPlain[] =
    "# a comment\n"
    "t,q_hip,tau_knee\n"
    "0,0.30000000000000004,-20\n"
    "0.001,1e-300,-5.5\n"
    "0.002,-0.7,nan\n";

TEST(ReadCsv, SpreadsheetDialectsReadAsThePlainFileToTheBit) {
  const CsvTable plain = ReadText("plain.csv", kPlain);
  ASSERT_EQ(plain.rows(), 3u);
  const std::string bom = "\xEF\xBB\xBF";
  ExpectSameTable(plain, ReadText("bom.csv", bom + kPlain), "UTF-8 byte-order mark");
  ExpectSameTable(plain,
                  ReadText("crlf.csv", "# a comment\r\nt,q_hip,tau_knee\r\n0,0.30000000000000004,-20\r\n"
                                       "0.001,1e-300,-5.5\r\n0.002,-0.7,nan\r\n"),
                  "CRLF line ends");
  ExpectSameTable(plain,
                  ReadText("quoted.csv", "# a comment\n\"t\",\"q_hip\",\"tau_knee\"\n"
                                         "\"0\",\"0.30000000000000004\",\"-20\"\n"
                                         "\"0.001\", \"1e-300\" ,-5.5\n\"0.002\",\"-0.7\",\"nan\"\n"),
                  "RFC 4180 quotes on names and values, blanks around a quoted field");
  ExpectSameTable(plain,
                  ReadText("trailing.csv", "# a comment\nt,q_hip,tau_knee,\n0,0.30000000000000004,-20,\n"
                                           "0.001,1e-300,-5.5,\n0.002,-0.7,nan,\n"),
                  "a trailing comma on every line");
  ExpectSameTable(plain,
                  ReadText("all.csv", bom + "# a comment\r\n\"t\",\"q_hip\",\"tau_knee\",\r\n"
                                            "\"0\",\"0.30000000000000004\",\"-20\",\r\n"
                                            "0.001,1e-300,\"-5.5\",\r\n0.002,-0.7,nan,\r\n"),
                  "all of them at once");
}

TEST(ReadCsv, AQuotedNameMayHoldACommaAndADoubledQuote) {
  const CsvTable t = ReadText("names.csv", "t,\"force, left\",\"say \"\"hi\"\"\",\"\"\"\"\n0,1,2,3\n");
  ASSERT_EQ(t.names.size(), 4u);
  EXPECT_EQ(t.names[1], "force, left");
  EXPECT_EQ(t.names[2], "say \"hi\"");
  EXPECT_EQ(t.names[3], "\"");
  EXPECT_EQ(t.Find("force, left"), 1);
  EXPECT_EQ(t.columns[3][0], 3.0);
  // A comma inside a quoted value is part of it: "1,5" is not a number (a decimal comma).
  const std::string e = ReadError("decimal_comma.csv", "t,a\n0,\"1,5\"\n");
  EXPECT_NE(e.find("decimal_comma.csv:2: column 'a': '1,5' is not a number"), std::string::npos) << e;
}

TEST(ReadCsv, NumbersAreWhatStrtodReadsInBothPaths) {
  // The unquoted fast path and the quoted path agree with strtod, to the bit, on every form.
  const char* forms[] = {"1.5", "-2e-3", "+1", "0x1p-3", "1e999", "-1e999", "1e-400", "4.9e-324",
                         "2.2250738585072011e-308", "inf", "-Infinity", "0.1", "123456789012345678901234567890"};
  for (const char* f : forms) {
    const CsvTable t = ReadText("forms.csv", std::string("a,b\n") + f + ",\"" + f + "\"\n");
    const double ref = std::strtod(f, nullptr);
    ASSERT_EQ(t.rows(), 1u) << f;
    EXPECT_EQ(0, std::memcmp(&t.columns[0][0], &ref, sizeof ref)) << f << " unquoted: " << t.columns[0][0];
    EXPECT_EQ(0, std::memcmp(&t.columns[1][0], &ref, sizeof ref)) << f << " quoted: " << t.columns[1][0];
  }
  for (const char* bad : {"1.5x", "1,5", "0x", "--1", "1 2", "", "e5", "\"\""}) {
    const std::string e = ReadError("bad_number.csv", std::string("a,b\n1,") + bad + "\n");
    EXPECT_NE(e.find("bad_number.csv:2: "), std::string::npos) << bad << ": " << e;
  }
}

TEST(ReadCsv, TrailingCommaRulesAreTheHeaders) {
  // The header has none: a row ending with ',' is one field too many.
  EXPECT_NE(ReadError("t1.csv", "t,a\n0,1\n1,2,\n").find("t1.csv:3: row ends with ','"), std::string::npos);
  // The header has one: every row must end with ',' and leave the column empty.
  std::string e = ReadError("t2.csv", "t,a,\n0,1,\n1,2\n");
  EXPECT_NE(e.find("t2.csv:3: expected 2 fields and a trailing ','"), std::string::npos) << e;
  e = ReadError("t3.csv", "t,a,\n0,1,\n1,2,7\n");
  EXPECT_NE(e.find("t3.csv:3: expected an empty last field (the header ends with ',')"), std::string::npos) << e;
  e = ReadError("t4.csv", "t,a,,\n0,1,,\n");
  EXPECT_NE(e.find("t4.csv:1: empty column name"), std::string::npos) << e;
}

TEST(ReadCsv, SemicolonsAndTabsNameTheSeparatorAndTheFix) {
  std::string e = ReadError("european.csv", "t;q_hip;q_knee\n0;0,3;-0,7\n");
  EXPECT_NE(e.find("european.csv:1: the header is separated by ';'"), std::string::npos) << e;
  EXPECT_NE(e.find("'.' as the decimal separator"), std::string::npos) << e;
  e = ReadError("tabs.csv", "\xEF\xBB\xBFt\tq_hip\n0\t0.3\n");
  EXPECT_NE(e.find("tabs.csv:1: the header is separated by tabs"), std::string::npos) << e;
  e = ReadError("mac.csv", "t,a\r0,1\r");
  EXPECT_NE(e.find("mac.csv:1: a carriage return inside the header line"), std::string::npos) << e;
}

TEST(ReadCsv, BrokenQuotesNameTheLineAndTheField) {
  std::string e = ReadError("open.csv", "t,a\n0,1\n1,\"2\n");
  EXPECT_NE(e.find("open.csv:3: field 2: a quoted field is not closed on its line"), std::string::npos) << e;
  e = ReadError("inner.csv", "t,a\n0,1\"2\n");
  EXPECT_NE(e.find("inner.csv:2: field 2: a '\"' inside an unquoted field"), std::string::npos) << e;
  e = ReadError("after.csv", "t,\"a\"b\n0,1\n");
  EXPECT_NE(e.find("after.csv:1: field 2: text after the closing quote"), std::string::npos) << e;
}

TEST(ReadCsv, AFolderNamesThePathAndWhatWasExpected) {
  const std::string dir = TempPath("a_folder.csv");
  std::filesystem::create_directories(dir);
  std::string e = ErrorOf([&] { ReadCsv(dir); });
  EXPECT_NE(e.find(dir + ": is a folder, expected a CSV file"), std::string::npos) << e;
  e = ReadError("bom_only.csv", "\xEF\xBB\xBF");
  EXPECT_NE(e.find("bom_only.csv: no header row"), std::string::npos) << e;
}

TEST(CsvReader, SplitsTextFieldsByTheSameRules) {
  const std::string text = "\xEF\xBB\xBF# c\r\nname, \"x, y\" ,n,\r\n\r\n\"a \"\"b\"\"\",,1.5,\r\n";
  CsvReader in(text, "s.csv");
  ASSERT_TRUE(in.ReadHeader());
  EXPECT_EQ(in.names(), (std::vector<std::string>{"name", "x, y", "n"}));
  ASSERT_TRUE(in.NextRow());
  EXPECT_EQ(in.line(), 4);
  EXPECT_EQ(in.field(0), "a \"b\"");
  EXPECT_EQ(in.field(1), "");
  double v = 0;
  EXPECT_FALSE(in.Number(1, &v));
  ASSERT_TRUE(in.Number(2, &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_FALSE(in.NextRow());
  EXPECT_EQ(in.Where(), "s.csv:4: ");
  const std::string empty = "# only\n\n";
  CsvReader none(empty, "e.csv");
  EXPECT_FALSE(none.ReadHeader());
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// A file of several read chunks (4 MiB each) reads as the whole text does, row for row and line for
// line, with a comment line longer than a chunk in the middle (the buffer grows for it).
TEST(ReadCsv, ChunkedReadingEqualsTheWholeText) {
  std::string text = "# long record\nt,a,b\n";
  for (int i = 0; i < 150000; ++i) {
    if (i == 70000) text += "# " + std::string(5 << 20, 'x') + "\n\n";
    text += std::to_string(i) + "," + std::to_string(std::sin(i) * 1e-3) + ", " + std::to_string(i % 7 - 3.5) + "\n";
  }
  text += "150000,1.5,2";  // no last newline: a row of a hand-written file
  const std::string path = TempPath("chunks.csv");
  Spit(path, text);
  const CsvTable t = ReadCsv(path);
  CsvReader in(text, "whole");
  ASSERT_TRUE(in.ReadHeader());
  ASSERT_EQ(t.names, in.names());
  double row[3];
  size_t r = 0;
  for (; in.NextNumbers(row); ++r) {
    ASSERT_LT(r, t.rows());
    for (int c = 0; c < 3; ++c) ASSERT_EQ(std::memcmp(&t.columns[c][r], &row[c], sizeof(double)), 0) << r;
    ASSERT_EQ(t.line_of_row[r], in.line()) << r;
  }
  EXPECT_EQ(r, t.rows());
  EXPECT_EQ(t.rows(), 150001u);
  EXPECT_EQ(t.dropped_cut_line, 0);
}

// A long chunk is read in two halves at once (ReadCsv): a bad field in the second half is named at its
// own line, and with another one in the first half that one, the file's first, is named instead.
TEST(ReadCsv, AnErrorInEitherHalfOfAChunkNamesTheFilesFirstBadLine) {
  auto File = [](const std::vector<int>& bad_rows) {
    std::string text = "t,x\n";
    text.reserve(14 << 20);
    for (int i = 0; i < 1200000; ++i) {
      const bool bad = std::find(bad_rows.begin(), bad_rows.end(), i) != bad_rows.end();
      text += std::to_string(i) + (bad ? ",x7\n" : ",0.5\n");
    }
    return text;
  };
  const std::string path = TempPath("halves.csv");
  // Rows are 10-12 bytes: row 600000 lies in the first half of the second 4 MiB chunk, 700000 in its second.
  for (const auto& [rows, line] : std::vector<std::pair<std::vector<int>, int>>{
           {{700000}, 700002}, {{600000, 700000}, 600002}, {{700000, 1100000}, 700002}}) {
    Spit(path, File(rows));
    try {
      ReadCsv(path);
      FAIL() << "expected an InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path + ":" + std::to_string(line) + ": column 'x': 'x7' is not a number");
    }
  }
  Spit(path, File({}));
  const CsvTable t = ReadCsv(path);
  ASSERT_EQ(t.rows(), 1200000u);
  for (size_t r = 0; r < t.rows(); r += 997) {
    ASSERT_EQ(t.columns[0][r], static_cast<double>(r));
    ASSERT_EQ(t.line_of_row[r], static_cast<int>(r) + 2);
  }
}

// A streamed log cut in a later chunk: every complete row kept, the cut line named.
TEST(ReadCsv, ACutAfterSeveralChunksNamesTheLine) {
  std::string text = std::string(kStreamMarker) + "\nt,x\n";
  for (int i = 0; i < 400000; ++i) text += std::to_string(i) + ",0.125\n";
  const std::string path = TempPath("cut_chunks.csv");
  Spit(path, text + "400000,0.1");
  ::testing::internal::CaptureStderr();
  const CsvTable t = ReadCsv(path);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(t.rows(), 400000u);
  EXPECT_EQ(t.dropped_cut_line, 400003);
  EXPECT_NE(err.find(path + ":400003: last line has no newline"), std::string::npos) << err;
}

// What the whole-file reading said first still comes first: a NUL byte late in the file before a bad
// field early in it; a cut last line's warning before the error.
TEST(ReadCsv, ANulByteAnywhereComesBeforeAParseError) {
  std::string text = "t,x\n1,oops\n";
  for (int i = 0; i < 1500000; ++i) text += "2,3\n";  // 6 MB: the NUL is in a later chunk
  const std::string path = TempPath("late_nul.csv");
  Spit(path, text + std::string(1, '\0') + "\n");
  try {
    ReadCsv(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": binary data (NUL byte) at line 1500003, byte 1, expected a text CSV file");
  }
  Spit(path, std::string(kStreamMarker) + "\n" + text + "4,");
  ::testing::internal::CaptureStderr();
  try {
    ReadCsv(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3: column 'x': 'oops' is not a number"), std::string::npos)
        << e.what();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(path + ":1500004: last line has no newline"), std::string::npos) << err;
}

// WriteCsv's shortest text reads back to the same double, for every kind of double.
TEST(WriteCsv, EveryNumberReadsBackToTheSameDouble) {
  std::vector<double> x = {0.0, -0.0, 1.0, 0.1, 1e-5, 1.0 / 3, -2.5e300, 4.9e-324, 2.2250738585072014e-308,
                           123456789012345678.0, 0.001, 1e22, 9007199254740993.0, -1e-7};
  for (int i = 0; i < 20000; ++i) x.push_back(std::ldexp(std::sin(i * 12.9898) * 43758.5453, i % 200 - 100));
  const std::string path = TempPath("roundtrip.csv");
  WriteCsv(path, {"x"}, {&x}, {"numbers"});
  const CsvTable t = ReadCsv(path);
  ASSERT_EQ(t.rows(), x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(std::memcmp(&t.columns[0][i], &x[i], sizeof(double)), 0) << i << " " << x[i];
    char b[40];
    std::snprintf(b, sizeof(b), "%.17g", x[i]);  // the text WriteCsv wrote before: the same double
    EXPECT_EQ(std::strtod(b, nullptr), t.columns[0][i]) << b;
  }
  EXPECT_NE(Slurp(path).find("\n1e-05\n"), std::string::npos);
}

}  // namespace
}  // namespace exotwin
