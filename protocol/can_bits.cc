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

// MSB-first bit string in bytes (at most 98 bits: a frame's stuff region).
struct BitString {
  uint8_t bytes[16] = {};
  int bits = 0;
  uint64_t acc = 0;  // bits not yet stored in bytes: the low (bits % 8) bits
  // Appends the k (<= 32) low bits of v, most significant first.
  void Put(uint32_t v, int k) {
    acc = (acc << k) | v;
    int pending = bits % 8 + k;
    bits += k;
    uint8_t* out = bytes + (bits - pending) / 8;
    while (pending >= 8) {
      pending -= 8;
      *out++ = static_cast<uint8_t>(acc >> pending);
    }
    if (pending > 0) *out = static_cast<uint8_t>(acc << (8 - pending));
  }
  bool Bit(int i) const { return ((bytes[i / 8] >> (7 - i % 8)) & 1) != 0; }
};

// CRC-15/CAN of the first n bits of s: whole bytes through kCrc15Table, the rest bit by bit.
uint16_t Crc15Of(const BitString& s, int n) {
  uint16_t crc = 0;
  const int whole = n / 8;
  for (int i = 0; i < whole; ++i) {
    const uint16_t x = static_cast<uint16_t>(crc ^ (s.bytes[i] << 7));
    crc = static_cast<uint16_t>(((x & 0x7F) << 8) ^ kCrc15Table[x >> 7]);
  }
  for (int i = 8 * whole; i < n; ++i) crc = Crc15Step(crc, s.Bit(i));
  return crc;
}

// Stuff bits of the first n bits of s: whole bytes through kStuffTable, the rest bit by bit.
int StuffBitsOf(const BitString& s, int n) {
  uint8_t state = StuffState(false, 0);
  int stuff = 0;
  const int whole = n / 8;
  for (int i = 0; i < whole; ++i) {
    const uint8_t e = kStuffTable[state][s.bytes[i]];
    stuff += e >> 4;
    state = e & 0x0F;
  }
  for (int i = 8 * whole; i < n; ++i) state = StuffStep(state, s.Bit(i), &stuff);
  return stuff;
}

}  // namespace

// Same bit stream as CanStuffRegion + CanStuffBitCount, without allocation and a byte at a time (CRC and
// stuffing by tables): this runs for every frame of the virtual bus (5 per millisecond).
// tests/protocol/can_bits_test.cc checks it against the bit-serial reference on random frames.
int CanFrameBits(const CanFrame& frame) {
  const int dlc = std::min<int>(frame.dlc, 8);
  BitString s;
  s.Put(0, 1);                  // SOF
  s.Put(frame.id & 0x7FF, 11);  // identifier
  s.Put(0, 3);                  // RTR, IDE, r0
  s.Put(frame.dlc & 0xF, 4);    // DLC as sent
  for (int i = 0; i < dlc; ++i) s.Put(frame.data[i], 8);
  s.Put(Crc15Of(s, s.bits), 15);  // CRC over SOF..data
  return s.bits + StuffBitsOf(s, s.bits) + kCanTrailerBits + kCanIfsBits;
}

int CanFrameBitsWorstCase(int dlc) {
  const int n = std::clamp(dlc, 0, 8);
  return 47 + 8 * n + (34 + 8 * n - 1) / 4;
}

}  // namespace exotwin
