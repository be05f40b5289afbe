// The DBC reader on small hand-written inputs: Intel and Motorola bit layouts, errors with lines.
#include "protocol/dbc.h"

#include <gtest/gtest.h>

#include <sstream>

#include "core/error.h"

namespace exotwin {
namespace {

DbcDatabase Parse(const std::string& text) {
  std::istringstream in(text);
  return ParseDbc(in, "test.dbc");
}

const char* kSmall = R"(VERSION ""
NS_ :
	CM_
BS_:
BU_: A B

BO_ 291 MSG: 8 A
 SG_ Intel16 : 8|16@1- (0.5,-1) [-16385|16382.5] "N m" B
 SG_ Moto16 : 39|16@0+ (1,0) [0|65535] "" B,A
 SG_ Nibble : 60|4@1+ (1,0) [0|15] "" B

CM_ SG_ 291 Intel16 "a comment
spanning two lines with BO_ 5 X: 1 A inside";
)";

TEST(Dbc, ParsesMessagesAndSignals) {
  const DbcDatabase db = Parse(kSmall);
  ASSERT_EQ(db.messages.size(), 1u);
  const DbcMessage& m = db.messages[0];
  EXPECT_EQ(m.id, 0x123u);
  EXPECT_EQ(m.name, "MSG");
  EXPECT_EQ(m.dlc, 8);
  EXPECT_EQ(m.sender, "A");
  ASSERT_EQ(m.signals.size(), 3u);
  const DbcSignal* s = m.Find("Intel16");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->start_bit, 8);
  EXPECT_EQ(s->length, 16);
  EXPECT_TRUE(s->little_endian);
  EXPECT_TRUE(s->is_signed);
  EXPECT_EQ(s->factor, 0.5);
  EXPECT_EQ(s->offset, -1);
  EXPECT_EQ(s->unit, "N m");
  EXPECT_EQ(m.Find("Moto16")->receivers, (std::vector<std::string>{"B", "A"}));
}

TEST(Dbc, DecodesHandPackedBytes) {
  const DbcMessage m = Parse(kSmall).messages[0];
  CanFrame f;
  f.dlc = 8;
  // Intel16 at bytes 1-2 little-endian: 0xFFFE = -2 -> -2 * 0.5 - 1 = -2.
  f.data = {0x00, 0xFE, 0xFF, 0x00, 0x12, 0x34, 0x00, 0xA0};
  EXPECT_DOUBLE_EQ(m.Find("Intel16")->Decode(f), -2.0);
  // Moto16 start bit 39 = MSB at byte 4 bit 7: big-endian bytes 4-5 = 0x1234.
  EXPECT_DOUBLE_EQ(m.Find("Moto16")->Decode(f), 0x1234);
  // Nibble: bits 60..63 = high nibble of byte 7 = 0xA.
  EXPECT_DOUBLE_EQ(m.Find("Nibble")->Decode(f), 10);
  // Encoding writes the same bytes back.
  CanFrame g;
  g.dlc = 8;
  m.Find("Intel16")->Encode(-2.0, &g);
  m.Find("Moto16")->Encode(0x1234, &g);
  m.Find("Nibble")->Encode(10, &g);
  EXPECT_EQ(g.data, f.data);
}

void ExpectErrorAtLine(const std::string& text, int line) {
  try {
    Parse(text);
    FAIL() << "no InputError for:\n" << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test.dbc:" + std::to_string(line) + ":"), std::string::npos) << e.what();
  }
}

TEST(Dbc, MalformedLinesNameTheLine) {
  ExpectErrorAtLine("BU_: A\nBO_ 12 M: 8\n", 2);                                   // sender missing
  ExpectErrorAtLine("BO_ 4096 M: 8 A\n", 1);                                        // not 11-bit
  ExpectErrorAtLine("BO_ 1 M: 9 A\n", 1);                                           // DLC > 8
  ExpectErrorAtLine("BO_ 1 M: 8 A\n SG_ X : 0|8@1+ (1,0) [0|1] \"\" B\n SG_ Y 0|8@1+\n", 3);
  ExpectErrorAtLine(" SG_ X : 0|8@1+ (1,0) [0|1] \"\" B\n", 1);                     // before BO_
  ExpectErrorAtLine("BO_ 1 M: 2 A\n\n SG_ X : 8|16@1+ (1,0) [0|1] \"\" B\n", 3);    // beyond 2 bytes
  ExpectErrorAtLine("BO_ 1 M: 8 A\n SG_ X : 0|8@1+ (abc,0) [0|1] \"\" B\n", 2);     // bad factor
  ExpectErrorAtLine("BO_ 1 M: 8 A\nBO_ 1 N: 8 A\n", 2);                             // duplicate id
}

TEST(Dbc, MissingFileIsInputError) { EXPECT_THROW(LoadDbc("/nonexistent/x.dbc"), InputError); }

}  // namespace
}  // namespace exotwin
