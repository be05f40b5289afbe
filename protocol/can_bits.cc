#include "protocol/can_bits.h"

#include <algorithm>

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

// Same bit stream as CanStuffRegion + CanStuffBitCount, on a stack buffer: this runs for every frame
// of the virtual bus (5 per millisecond), so it must not allocate. tests/protocol/can_bits_test.cc
// checks both paths agree on random frames.
int CanFrameBits(const CanFrame& frame) {
  const int dlc = std::min<int>(frame.dlc, 8);
  uint8_t bits[34 + 64];
  int n = 0;
  auto push = [&](uint32_t value, int k) {
    for (int i = k - 1; i >= 0; --i) bits[n++] = static_cast<uint8_t>((value >> i) & 1u);
  };
  push(0, 1);                 // SOF
  push(frame.id & 0x7FF, 11); // identifier
  push(0, 3);                 // RTR, IDE, r0
  push(frame.dlc & 0xF, 4);   // DLC
  for (int i = 0; i < dlc; ++i) push(frame.data[i], 8);
  uint16_t crc = 0;
  for (int i = 0; i < n; ++i) {
    const bool top = ((crc >> 14) & 1u) != 0;
    crc = static_cast<uint16_t>((crc << 1) & 0x7FFF);
    if (top != (bits[i] != 0)) crc ^= 0x4599;
  }
  push(crc, 15);
  int stuff = 0, run = 0;
  uint8_t last = 0;
  for (int i = 0; i < n; ++i) {
    if (run > 0 && bits[i] == last) {
      ++run;
    } else {
      last = bits[i];
      run = 1;
    }
    if (run == 5) {
      ++stuff;
      last = static_cast<uint8_t>(!last);
      run = 1;
    }
  }
  return n + stuff + kCanTrailerBits + kCanIfsBits;
}

int CanFrameBitsWorstCase(int dlc) {
  const int n = std::clamp(dlc, 0, 8);
  return 47 + 8 * n + (34 + 8 * n - 1) / 4;
}

}  // namespace exotwin
