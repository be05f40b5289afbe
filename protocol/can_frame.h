// A classic CAN 2.0A frame: 11-bit identifier, 0..8 data bytes. Also carries error frames
// (error = true; id, dlc and data are then meaningless) so every backend reports them the same way.
#pragma once
#include <array>
#include <cstdint>

namespace exotwin {

struct CanFrame {
  uint16_t id = 0;                // 11-bit identifier, 0x000..0x7FF (lower wins arbitration)
  uint8_t dlc = 0;                // number of data bytes, 0..8
  std::array<uint8_t, 8> data{};  // bytes beyond dlc are ignored (and kept zero by the codec)
  double t = 0;                   // s, simulated time stamp of reception (or transmission)
  bool error = false;             // true: an error frame (a transmission destroyed by a bus error)
};

constexpr uint16_t kCanMaxId = 0x7FF;
constexpr uint8_t kCanMaxDlc = 8;

// True when the frame can be put on a classic CAN bus: id <= 0x7FF, dlc <= 8, not an error frame.
inline bool IsValidDataFrame(const CanFrame& f) { return !f.error && f.id <= kCanMaxId && f.dlc <= kCanMaxDlc; }

// Same identifier, length and payload bytes [0, dlc) and error flag; the time stamp is not compared.
inline bool SamePayload(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.dlc != b.dlc || a.error != b.error) return false;
  for (int i = 0; i < a.dlc && i < 8; ++i)
    if (a.data[i] != b.data[i]) return false;
  return true;
}

}  // namespace exotwin
