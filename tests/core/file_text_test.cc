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
            dir + "/nul.yaml: binary data (NUL byte) at line 2, byte 1, expected a YAML text file");
  std::ofstream(dir + "/latin1.csv", std::ios::binary) << "t,q_hip\n# 90\xb0 flexion\n";
  EXPECT_EQ(MessageOf(dir + "/latin1.csv", "", "a text CSV file"),
            dir + "/latin1.csv: invalid UTF-8 (byte 0xB0) at line 2, byte 5, expected a text CSV file");
  std::ofstream(dir + "/cut.yaml", std::ios::binary) << "name: caf\xc3";
  EXPECT_EQ(MessageOf(dir + "/cut.yaml", "", "a YAML text file"),
            dir + "/cut.yaml: invalid UTF-8 (sequence 0xC3 cut by the end of the text) at line 1, byte 10, expected a YAML text file");
}

// ReadBinaryFile: every byte as stored (NUL, invalid UTF-8), the open errors as ReadTextFile's.
// ShownText: a string from a binary file quoted only when it is valid text.
TEST(FileText, BinaryFilesAndShownText) {
  const testing::ScopedTempDir tmp("file_text");
  const std::string& dir = tmp.path();
  const std::string bytes("\x89MCAP0\r\n\0\xff\xc3", 11);
  std::ofstream(dir + "/b.mcap", std::ios::binary) << bytes;
  EXPECT_EQ(ReadBinaryFile(dir + "/b.mcap", "MCAP"), bytes);
  try {
    ReadBinaryFile(dir + "/none.mcap", "MCAP");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/none.mcap: cannot open MCAP file (No such file or directory)");
  }
  EXPECT_EQ(ShownText("/exo/joint_states"), "/exo/joint_states");
  EXPECT_EQ(ShownText("caf\xc3\xa9"), "caf\xc3\xa9");
  EXPECT_EQ(ShownText(std::string("a\0b", 3)), "<3 bytes, not text>");
  EXPECT_EQ(ShownText("\xff"), "<1 bytes, not text>");
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

namespace exotwin {
namespace {

std::string FaultOf(std::string_view text) {
  const auto f = FindTextFault(text);
  return f ? f->Where() : "none";
}

// The text check: every UTF-8 form nlohmann::json and a browser accept passes; every byte sequence
// they refuse, and every control character but tab, LF and CR, is named with its line and byte.
TEST(TextCheck, AcceptsUtf8TextAndNamesTheFirstFault) {
  EXPECT_EQ(FaultOf(""), "none");
  EXPECT_EQ(FaultOf("\xef\xbb\xbft,q\r\n\tcaf\xc3\xa9 \xe2\x82\xac \xf0\x9d\x84\x9e \xc2\xa0 \xf4\x8f\xbf\xbf \xed\x9f\xbf\n"),
            "none");
  EXPECT_EQ(FaultOf("ab\ncd\x07"), "control character 0x07 at line 2, byte 3");
  EXPECT_EQ(FaultOf("a\x1b[0m"), "control character 0x1B at line 1, byte 2");
  EXPECT_EQ(FaultOf("a\x7f"), "control character 0x7F at line 1, byte 2");
  EXPECT_EQ(FaultOf(std::string_view("a\0", 2)), "binary data (NUL byte) at line 1, byte 2");
  // A binary file is named as such, even where an invalid byte comes before its NUL.
  EXPECT_EQ(FaultOf(std::string_view("\xc1\n a\0", 5)), "binary data (NUL byte) at line 2, byte 3");
  EXPECT_EQ(FaultOf("\xc2\x85"), "control character U+0085 (C1) at line 1, byte 1");
  EXPECT_EQ(FaultOf("x\x80"), "invalid UTF-8 (byte 0x80) at line 1, byte 2");
  EXPECT_EQ(FaultOf("\xc1\xbf"), "invalid UTF-8 (byte 0xC1) at line 1, byte 1");           // overlong
  EXPECT_EQ(FaultOf("\xe0\x9f\xbf"), "invalid UTF-8 (byte 0xE0 followed by 0x9F) at line 1, byte 1");  // overlong
  EXPECT_EQ(FaultOf("\xed\xa0\x80"), "invalid UTF-8 (byte 0xED followed by 0xA0) at line 1, byte 1");  // surrogate
  EXPECT_EQ(FaultOf("\xf0\x8f\xbf\xbf"), "invalid UTF-8 (byte 0xF0 followed by 0x8F) at line 1, byte 1");
  EXPECT_EQ(FaultOf("\xf4\x90\x80\x80"), "invalid UTF-8 (byte 0xF4 followed by 0x90) at line 1, byte 1");  // > U+10FFFF
  EXPECT_EQ(FaultOf("\xf5\x80\x80\x80"), "invalid UTF-8 (byte 0xF5) at line 1, byte 1");
  EXPECT_EQ(FaultOf("\xe2\x82\n"), "invalid UTF-8 (byte 0xE2 followed by 0x0A) at line 1, byte 1");
  EXPECT_EQ(FaultOf("\n\n\xe2\x82"), "invalid UTF-8 (sequence 0xE2 cut by the end of the text) at line 3, byte 1");
  EXPECT_THROW(CheckText("a\xff", "s.yaml", "a YAML text"), InputError);
  try {
    CheckText("ok\nname: \xc1x\n", "s.yaml", "a YAML text");
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "s.yaml: invalid UTF-8 (byte 0xC1) at line 2, byte 7, expected a YAML text");
  }
}

// Fed in pieces, a sequence split between two pieces is whole; lines and bytes count across pieces.
TEST(TextCheck, PiecesGiveTheSameVerdictAsTheWhole) {
  const std::string text = "a\n\xe2\x82\xac\nbb\xf0\x9d\x84\x9e\ncc\xed\xa0\x80";
  for (size_t cut = 0; cut <= text.size(); ++cut) {
    TextCheck c;
    const bool ok = c.Feed(text.data(), cut) && c.Feed(text.data() + cut, text.size() - cut) && c.End();
    EXPECT_FALSE(ok);
    ASSERT_TRUE(c.fault());
    EXPECT_EQ(c.fault()->Where(), "invalid UTF-8 (byte 0xED followed by 0xA0) at line 4, byte 3") << cut;
  }
  TextCheck c;
  EXPECT_TRUE(c.Feed("\xe2", 1) && c.Feed("\x82", 1) && c.Feed("\xac", 1) && c.End());
}

// Eight bytes are checked at once where they are printable ASCII: a fault at any place in a long text
// is found and placed as byte by byte.
TEST(TextCheck, LongTextsPlaceTheFaultExactly) {
  for (const char bad : {'\x7f', '\x1f', '\x01', '\x80', '\xff'}) {
    for (size_t k = 0; k < 40; ++k) {
      std::string text = "line one\tand tab\r\n" + std::string(k, 'a');
      text += bad;
      text += std::string(30, 'z');
      ASSERT_TRUE(FindTextFault(text)) << k;
      EXPECT_EQ(FindTextFault(text)->line, 2u);
      EXPECT_EQ(FindTextFault(text)->byte, k + 1) << int(bad);
    }
  }
  EXPECT_FALSE(FindTextFault(std::string(1000, '~') + "\t\r\n" + std::string(1000, ' ')));
}

// Every command-line value is checked before any is used; the byte is counted in the whole value.
TEST(TextCheck, CommandLineValues) {
  const char* good[] = {"exotwin", "run", "sc\xc3\xa9nario.yaml", "--out", "out/x"};
  CheckCommandLine(5, good);
  const char* bad[] = {"exotwin", "run", "s.yaml", "--out", "a\nb\xc1"};
  try {
    CheckCommandLine(5, bad);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "command line: argument 4: invalid UTF-8 (byte 0xC1) at byte 4, expected UTF-8 text");
  }
}

}  // namespace
}  // namespace exotwin
