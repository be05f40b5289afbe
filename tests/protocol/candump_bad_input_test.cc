// Candump logs in the bad-input matrix of issue 8 (no subcommand reads a candump log yet, so the
// reader is tested directly): each case throws InputError naming file and line and what was
// expected. Complements tests/protocol/candump_test.cc (malformed-line cases are not repeated here).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "core/error.h"
#include <unistd.h>
#include "protocol/candump.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

std::string WriteLog(const std::string& tag, const std::string& content) {
  static const testing::ScopedTempDir tmp("candump_bad");  // the suite's folder, removed at exit
  const std::string path = tmp.File(tag + ".log");
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

void ExpectBad(const std::string& tag, const std::string& content, const std::string& place_suffix,
               const std::string& expected) {
  const std::string path = WriteLog(tag, content);
  try {
    CandumpReader::ReadAll(path);
    ADD_FAILURE() << tag << ": accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path + place_suffix), std::string::npos) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected '(sec.usec) can0 ID#DATA'"), std::string::npos) << msg;
  }
  std::remove(path.c_str());
}

const char kGood[] = "(1700000000.000000) can0 101#0102\n(1700000000.001000) can0 102#03\n";

TEST(CandumpBadInput, TruncatedLastLine) {
  ExpectBad("truncated", std::string(kGood) + "(1700000000.00", ":3:", "missing ')' after the time stamp");
}
// Text that is not valid (core/file_text.h: UTF-8 without control characters) is refused before its
// line is parsed, naming the line and the byte.
void ExpectBadText(const std::string& tag, const std::string& content, const std::string& fault) {
  const std::string path = WriteLog(tag, content);
  try {
    CandumpReader::ReadAll(path);
    ADD_FAILURE() << tag << ": accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": " + fault + ", expected a candump log");
  }
  std::remove(path.c_str());
}

TEST(CandumpBadInput, BinaryJunkWithNul) {
  ExpectBadText("junk_nul", std::string("\x01\x02\0\xff\xfe junk\n", 11), "binary data (NUL byte) at line 1, byte 3");
}
TEST(CandumpBadInput, BinaryJunkHighBytes) {
  ExpectBadText("junk_high", std::string(kGood) + "(\xc3\x28\xa0\xa1.\xe2\x82) can0 1#\n",
                "invalid UTF-8 (byte 0xC3 followed by 0x28) at line 3, byte 2");
  ExpectBadText("junk_ctrl", std::string(kGood) + "(1700000000.002000) can\x1b" "0 103#00\n",
                "control character 0x1B at line 3, byte 24");
}
TEST(CandumpBadInput, HugeTimeStamp) {
  ExpectBad("huge_stamp", "(99999999999999999999999.000001) can0 123#00\n", ":1:", "time stamp out of range");
}
TEST(CandumpBadInput, TooManyDecimals) {
  ExpectBad("decimals", "(1700000000.0000000001) can0 123#00\n", ":1:", "more than 9 decimals");
}
TEST(CandumpBadInput, DataNotHexadecimal) {
  ExpectBad("data_hex", std::string(kGood) + "(1700000000.002000) can0 103#0Z\n", ":3:", "data is not hexadecimal");
}
TEST(CandumpBadInput, EmptyFileIsAnEmptyLog) {
  const std::string path = WriteLog("empty", "");
  EXPECT_TRUE(CandumpReader::ReadAll(path).empty());
  std::remove(path.c_str());
}

}  // namespace
}  // namespace exotwin
