#include "protocol/can_bits.h"

#include <algorithm>
#include <array>

namespace exotwin {

uint16_t CanCrc15(const std::vector<bool>& bits) {
  uint16_t crc = 0;
  for (bool b : bits) {
    const bool top = ((crc >> 14) & 1u) != 0;
    crc = static_cast<uint16_t>((crc << 1) & 0x7FFF);
    if (top != b) crc ^= 0x4599;
  }
  return crc;
}

uint16_t CanCrc15Bytes(const std::vector<uint8_t>& bytes) {
  std::vector<bool> bits;
  for (uint8_t byte : bytes)
    for (int i = 7; i >= 0; --i) bits.push_back(((byte >> i) & 1) != 0);
  return CanCrc15(bits);
}

namespace {
void PushBits(std::vector<bool>* bits, uint32_t value, int n) {
  for (int i = n - 1; i >= 0; --i) bits->push_back(((value >> i) & 1u) != 0);
}
}  // namespace

std::vector<bool> CanStuffRegion(const CanFrame& frame) {
  const int dlc = std::min<int>(frame.dlc, 8);
  std::vector<bool> bits;
  bits.reserve(34 + 8 * dlc);
  bits.push_back(false);                 // SOF (dominant)
  PushBits(&bits, frame.id & 0x7FF, 11); // identifier
  bits.push_back(false);                 // RTR: data frame
  bits.push_back(false);                 // IDE: standard frame
  bits.push_back(false);                 // r0
  PushBits(&bits, frame.dlc & 0xF, 4);   // DLC as sent
  for (int i = 0; i < dlc; ++i) PushBits(&bits, frame.data[i], 8);
  PushBits(&bits, CanCrc15(bits), 15);   // CRC over SOF..data
  return bits;
}

int CanStuffBitCount(const std::vector<bool>& bits) {
  int stuff = 0, run = 0;
  bool last = false;
  for (bool b : bits) {
    if (run > 0 && b == last) {
      ++run;
    } else {
      last = b;
      run = 1;
    }
    if (run == 5) {  // insert the complement; it starts a new run of length 1
      ++stuff;
      last = !last;
      run = 1;
    }
  }
  return stuff;
}

namespace {

// One step of the bit-serial CRC-15/CAN register (ISO 11898-1 sec. 10.4.2.6): shift in bit b.
constexpr uint16_t Crc15Step(uint16_t crc, bool b) {
  const bool top = ((crc >> 14) & 1u) != 0;
  crc = static_cast<uint16_t>((crc << 1) & 0x7FFF);
  return top != b ? static_cast<uint16_t>(crc ^ 0x4599) : crc;
}

// kCrc15Table[i]: the register i << 7 after 8 zero input bits. Shifting in a byte B (MSB first) is
// then x = crc ^ (B << 7); crc' = ((x & 0x7F) << 8) ^ kCrc15Table[x >> 7] (the low 7 bits of x reach
// bit 14 only after the 8th shift, so they never feed back within the byte).
constexpr std::array<uint16_t, 256> MakeCrc15Table() {
  std::array<uint16_t, 256> t{};
  for (int i = 0; i < 256; ++i) {
    uint16_t crc = static_cast<uint16_t>(i << 7);
    for (int k = 0; k < 8; ++k) crc = Crc15Step(crc, false);
    t[i] = crc;
  }
  return t;
}
constexpr std::array<uint16_t, 256> kCrc15Table = MakeCrc15Table();

// The transmitter's stuffing state before a bit: the last bit sent (stuff bits included) and the
// length of the run of equal bits it ends, 1..4 (a run of 5 is stuffed at once); run 0 before the
// first bit. Packed as last * 5 + run (10 states).
constexpr int kStuffStates = 10;
constexpr uint8_t StuffState(bool last, int run) { return static_cast<uint8_t>((last ? 5 : 0) + run); }

// One bit through the stuffing state: returns the new state, adds the inserted stuff bits to *stuff
// (same rule as CanStuffBitCount).
constexpr uint8_t StuffStep(uint8_t state, bool b, int* stuff) {
  bool last = state >= 5;
  int run = state % 5;
  if (run > 0 && b == last) {
    ++run;
  } else {
    last = b;
    run = 1;
  }
  if (run == 5) {  // the complement is inserted and starts a new run
    ++*stuff;
    last = !last;
    run = 1;
  }
  return StuffState(last, run);
}

// kStuffTable[state][byte] = new state | stuff bits inserted while sending the byte MSB first << 4
// (at most 2 per byte).
constexpr std::array<std::array<uint8_t, 256>, kStuffStates> MakeStuffTable() {
  std::array<std::array<uint8_t, 256>, kStuffStates> t{};
  for (int s = 0; s < kStuffStates; ++s)
    for (int byte = 0; byte < 256; ++byte) {
      uint8_t state = static_cast<uint8_t>(s);
      int stuff = 0;
      for (int i = 7; i >= 0; --i) state = StuffStep(state, ((byte >> i) & 1) != 0, &stuff);
      t[s][byte] = static_cast<uint8_t>(state | (stuff << 4));
    }
  return t;
}
constexpr std::array<std::array<uint8_t, 256>, kStuffStates> kStuffTable = MakeStuffTable();

// A byte (MSB first) through the CRC register.
inline uint16_t Crc15Byte(uint16_t crc, uint32_t byte) {
  const uint32_t x = crc ^ (byte << 7);
  return static_cast<uint16_t>(((x & 0x7F) << 8) ^ kCrc15Table[x >> 7]);
}

}  // namespace

// Same bit stream as CanStuffRegion + CanStuffBitCount, without allocation and mostly a byte at a time
// (CRC and stuffing by tables): this runs for every frame of the virtual bus (5 per millisecond).
// tests/protocol/can_bits_test.cc checks it against the bit-serial reference for every ID and DLC.
int CanFrameBits(const CanFrame& frame) {
  const int n = std::min<int>(frame.dlc, 8);
  const uint32_t id = frame.id & 0x7FFu, dlc = frame.dlc & 0xFu;
  // CRC over SOF..data (19 + 8n bits): SOF and ID bits 10, 9 one at a time, then whole bytes: ID bits
  // 8..0 + RTR, IDE, r0 (dominant) + DLC (16 bits), then the data.
  uint16_t crc = Crc15Step(0, false);
  crc = Crc15Step(crc, ((id >> 10) & 1u) != 0);
  crc = Crc15Step(crc, ((id >> 9) & 1u) != 0);
  const uint32_t head16 = ((id & 0x1FFu) << 7) | dlc;
  crc = Crc15Byte(crc, head16 >> 8);
  crc = Crc15Byte(crc, head16 & 0xFFu);
  for (int i = 0; i < n; ++i) crc = Crc15Byte(crc, frame.data[i]);
  // Stuffing over SOF..CRC (34 + 8n bits): SOF and ID bit 10 one at a time, then the remaining
  // 32 + 8n bits (ID 9..0, RTR, IDE, r0, DLC, data, CRC) in whole bytes from a bit accumulator.
  int stuff = 0;
  uint8_t state = StuffStep(StuffState(false, 0), false, &stuff);
  state = StuffStep(state, ((id >> 10) & 1u) != 0, &stuff);
  uint64_t acc = ((id & 0x3FFu) << 7) | dlc;  // 17 bits pending
  int pending = 17;
  auto drain = [&]() {
    while (pending >= 8) {
      pending -= 8;
      const uint8_t e = kStuffTable[state][(acc >> pending) & 0xFFu];
      stuff += e >> 4;
      state = e & 0x0F;
    }
  };
  for (int i = 0; i < n; ++i) {
    acc = (acc << 8) | frame.data[i];
    pending += 8;
    drain();
  }
  acc = (acc << 15) | crc;
  pending += 15;
  drain();
  return 34 + 8 * n + stuff + kCanTrailerBits + kCanIfsBits;
}

int CanFrameBitsWorstCase(int dlc) {
  const int n = std::clamp(dlc, 0, 8);
  return 47 + 8 * n + (34 + 8 * n - 1) / 4;
}

}  // namespace exotwin
