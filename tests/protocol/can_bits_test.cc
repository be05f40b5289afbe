// Frame bit counts against hand-counted bit streams. CRC values in the comments come from a long
// division by x^15+x^14+x^10+x^8+x^7+x^4+x^3+1 done outside this code (a separate Python script),
// and the CRC routine itself is checked against the published CRC-15/CAN check value.
#include "protocol/can_bits.h"

#include <gtest/gtest.h>

#include <random>

namespace exotwin {
namespace {

CanFrame Frame(uint16_t id, std::vector<uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<uint8_t>(bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) f.data[i] = bytes[i];
  return f;
}

std::vector<bool> Bits(const std::string& s) {
  std::vector<bool> b;
  for (char c : s) b.push_back(c == '1');
  return b;
}

TEST(CanCrc15, PublishedCheckValue) {
  // CRC catalogue (reveng), CRC-15/CAN: width 15, poly 0x4599, init 0, check("123456789") = 0x059E.
  EXPECT_EQ(CanCrc15Bytes({'1', '2', '3', '4', '5', '6', '7', '8', '9'}), 0x059E);
}

TEST(CanStuffing, StuffBitStartsTheNextRun) {
  EXPECT_EQ(CanStuffBitCount(Bits("0000")), 0);
  EXPECT_EQ(CanStuffBitCount(Bits("00000")), 1);        // a run ending the sequence is stuffed too
  EXPECT_EQ(CanStuffBitCount(Bits("0101010101")), 0);
  // 00000 [1] 1111 [0] 1 : the inserted 1 counts in the run of ones -> two stuff bits.
  EXPECT_EQ(CanStuffBitCount(Bits("0000011111")), 2);
  // 00000 [1] 1111 [0]: the inserted 1 and the next four 1s make a run of five -> a second stuff bit.
  EXPECT_EQ(CanStuffBitCount(Bits("000001111")), 2);
  EXPECT_EQ(CanStuffBitCount(Bits("00000111")), 1);
  // 00000 [1] 00000 [1]: the inserted 1 breaks the zeros, five more zeros need another one.
  EXPECT_EQ(CanStuffBitCount(Bits("0000000000")), 2);
  EXPECT_EQ(CanStuffBitCount(Bits("000000000")), 1);
}

TEST(CanFrameBits, Id000NoData) {
  // SOF 0 | ID 00000000000 | RTR 0 IDE 0 r0 0 | DLC 0000 = 19 zeros; CRC of all zeros = 0 (15 zeros).
  // Stuff region = 34 zeros -> a stuff bit after zeros 5, 10, 15, 20, 25, 30 = 6 stuff bits.
  // 34 + 6 + CRC delim 1 + ACK 2 + EOF 7 + IFS 3 = 53 bits.
  CanFrame f = Frame(0x000, {});
  EXPECT_EQ(CanStuffRegion(f).size(), 34u);
  EXPECT_EQ(CanFrameBits(f), 53);
}

TEST(CanFrameBits, Id555OneByte55) {
  // SOF 0 | ID 10101010101 | 000 | DLC 0001 | data 01010101 | CRC 111100010010111 (= 0x7897)
  //   0 10101010101 000 0001 01010101 111100010010111      (42 bits)
  // runs of 5: "000 000" (RTR IDE r0 + DLC 000) -> 1 stuff; data's last 1 + CRC's 1111 -> 1 stuff.
  // 42 + 2 + 10 + 3 = 57 bits.
  CanFrame f = Frame(0x555, {0x55});
  const std::vector<bool> region = CanStuffRegion(f);
  EXPECT_EQ(region, Bits("010101010101000000101010101111100010010111"));
  EXPECT_EQ(CanStuffBitCount(region), 2);
  EXPECT_EQ(CanFrameBits(f), 57);
}

TEST(CanFrameBits, Id555EightBytes55) {
  // 0 10101010101 000 1000 (01010101 x 8) CRC 001101100000100 (= 0x1B04): the data alternate, but
  // the CRC holds "00000" -> exactly one stuff bit. 98 + 1 + 13 = 112 bits.
  CanFrame f = Frame(0x555, {0x55, 0x55, 0x55, 0x55, 0x55, 0x55, 0x55, 0x55});
  EXPECT_EQ(CanStuffRegion(f).size(), 98u);
  EXPECT_EQ(CanFrameBits(f), 112);
}

TEST(CanFrameBits, Id000EightZeroBytes) {
  // 0 00000000000 000 1000 (64 zeros) CRC 001010001011011 (= 0x145B). Stuffed stream:
  //   00000[1]00000[1]00000[1]1000[0]... hand count: first 15 zeros -> 3 stuff bits; DLC "1": then
  //   "000" + 64 data zeros + CRC "00" = 69 zeros preceded by the stuff bit/1 -> 13 stuff bits;
  //   CRC rest "1010001011011" has no run of 5. Total 16 stuff bits: 98 + 16 + 13 = 127 bits.
  CanFrame f = Frame(0x000, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(CanStuffBitCount(CanStuffRegion(f)), 16);
  EXPECT_EQ(CanFrameBits(f), 127);
}

TEST(CanFrameBits, Id7FFEightFFBytes) {
  // 0 11111111111 000 1000 (64 ones) CRC 100110010001001 (= 0x4C89): 11 ID ones -> 2 stuff bits;
  // "0001000" none; 64 data ones + the CRC's leading 1 = 65 ones -> 13; rest of the CRC none.
  // 15 stuff bits: 98 + 15 + 13 = 126.
  CanFrame f = Frame(0x7FF, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF});
  EXPECT_EQ(CanStuffBitCount(CanStuffRegion(f)), 15);
  EXPECT_EQ(CanFrameBits(f), 126);
}

TEST(CanFrameBits, WorstCaseFormulaOfDavisEtAl) {
  // Davis, Burns, Bril, Lukkien (2007): 8-byte standard frame <= 135 bits, 0-byte <= 55 bits.
  EXPECT_EQ(CanFrameBitsWorstCase(8), 135);
  EXPECT_EQ(CanFrameBitsWorstCase(0), 55);
  std::mt19937_64 gen(7);
  for (int k = 0; k < 2000; ++k) {
    CanFrame f;
    f.id = static_cast<uint16_t>(gen() & 0x7FF);
    f.dlc = static_cast<uint8_t>(gen() % 9);
    for (int i = 0; i < f.dlc; ++i) f.data[i] = static_cast<uint8_t>(gen() & (k % 2 ? 0xFF : 0x01));
    const int bits = CanFrameBits(f);
    EXPECT_GE(bits, 47 + 8 * f.dlc);
    EXPECT_LE(bits, CanFrameBitsWorstCase(f.dlc));
  }
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// The allocation-free CanFrameBits and the vector-based region + stuff count agree on random frames.
TEST(CanFrameBits, FastPathAgreesWithBitStream) {
  uint64_t x = 88172645463325252ull;  // xorshift64
  auto next = [&]() { x ^= x << 13; x ^= x >> 7; x ^= x << 17; return x; };
  for (int k = 0; k < 5000; ++k) {
    CanFrame f;
    f.id = static_cast<uint16_t>(next() & 0x7FF);
    f.dlc = static_cast<uint8_t>(next() % 9);
    for (int i = 0; i < f.dlc; ++i) f.data[i] = static_cast<uint8_t>((k % 3 == 0) ? (next() & 1 ? 0 : 0xFF) : next());
    const std::vector<bool> region = CanStuffRegion(f);
    EXPECT_EQ(CanFrameBits(f), static_cast<int>(region.size()) + CanStuffBitCount(region) + kCanTrailerBits + kCanIfsBits);
  }
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

// The table-driven CanFrameBits against the bit-serial reference for every identifier with every DLC
// code 0..15 (9..15 send 8 bytes), random payloads and the all-equal payloads that stuff most.
TEST(CanFrameBits, TablesAgreeWithBitSerialReferenceForEveryIdAndDlc) {
  std::mt19937_64 gen(16);
  for (int id = 0; id <= 0x7FF; ++id)
    for (int dlc = 0; dlc <= 15; ++dlc) {
      CanFrame f;
      f.id = static_cast<uint16_t>(id);
      f.dlc = static_cast<uint8_t>(dlc);
      const uint64_t pattern = gen();
      for (int i = 0; i < 8; ++i)
        f.data[i] = static_cast<uint8_t>(id % 3 == 0 ? 0x00 : id % 3 == 1 ? 0xFF : pattern >> (8 * i));
      const std::vector<bool> region = CanStuffRegion(f);
      ASSERT_EQ(CanFrameBits(f), static_cast<int>(region.size()) + CanStuffBitCount(region) + kCanTrailerBits +
                                     kCanIfsBits)
          << "id " << id << " dlc " << dlc;
    }
}

}  // namespace
}  // namespace exotwin
