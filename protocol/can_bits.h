// The bit-level layout of a classic CAN 2.0A data frame (ISO 11898-1), used for frame durations:
// SOF, 11-bit ID, RTR, IDE, r0, 4-bit DLC, data, CRC-15 -- the stuffed part -- then CRC delimiter,
// ACK slot + delimiter, 7-bit EOF and the 3-bit intermission (IFS).
#pragma once
#include <cstdint>
#include <vector>

#include "protocol/can_frame.h"

namespace exotwin {

// Bits after the stuffed part: CRC delimiter 1 + ACK slot 1 + ACK delimiter 1 + EOF 7.
constexpr int kCanTrailerBits = 10;
// Intermission between frames (bits the bus stays recessive before the next SOF).
constexpr int kCanIfsBits = 3;
// Error flag (6) + error delimiter (8): what a bus error adds after the point of detection.
constexpr int kCanErrorFrameBits = 14;

// CRC-15/CAN (polynomial 0x4599, init 0) of a bit sequence, most significant (first sent) bit first.
uint16_t CanCrc15(const std::vector<bool>& bits);
// CRC-15/CAN of whole bytes, MSB first (for checking against the published check value).
uint16_t CanCrc15Bytes(const std::vector<uint8_t>& bytes);
// The unstuffed bits SOF..CRC of a data frame (34 + 8 * dlc bits); dlc is clamped to 8.
std::vector<bool> CanStuffRegion(const CanFrame& frame);
// Number of stuff bits the transmitter inserts into a bit sequence (one after every run of five
// equal bits, the stuff bit itself starting the next run; a run ending the sequence is stuffed too).
int CanStuffBitCount(const std::vector<bool>& bits);
// Bits on the wire for this data frame including actual stuffing, trailer and IFS (47 + 8n + stuff).
int CanFrameBits(const CanFrame& frame);
// Worst-case bits of a data frame with dlc bytes (Davis et al. 2007: 47 + 8n + floor((34 + 8n - 1) / 4)).
int CanFrameBitsWorstCase(int dlc);

}  // namespace exotwin
