// The frames of the twin-controller link beyond the device messages of protocol/messages.h
// (DESIGN.md "The CAN transport between processes"). Values are IEEE-754 doubles, little-endian,
// DLC 8, so the simulated times and the controller's telemetry cross the process boundary exactly.
//   0x000 NMT (CANopen): twin -> controller. data[0] 0x01 start (data[2] the trial, 0-based: the
//         controller starts a fresh control loop; data[3..4] the start's sequence number in the session,
//         little-endian, the same for the repeats of one start), 0x02 stop (the session is over: the
//         controller exits).
//   0x080 SYNC (CANopen COB-ID): twin -> controller, once per controller period; data: the tick's
//         simulated time t (s). The controller ticks at t on the frames received before it.
//   0x701 boot-up / ready: controller -> twin, answer to an NMT start; data[0] 0x05, data[1] the trial,
//         data[2..3] the start's sequence number.
//   0x780 + i telemetry: controller -> twin after each tick, i = TelemetryIndex (EXOwheel) or
//         HalTelemetryIndex (HAL-3): the value logged.
//   0x7F0 cycle done: controller -> twin, last frame of a tick; data: the SYNC's t echoed.
//   0x702 configuration request: controller -> twin, answer to every NMT start by a controller started on
//         a scenario file (its feed-forward model, reference or EMG calibration are the twin's, and may
//         change from one run or trial to the next): data[1] the trial, data[2..3] the start's sequence.
//   0x7E0 configuration data: twin -> controller, the controller file's text (DESIGN.md "Controller
//         file"), DLC 1..8 bytes per frame, in order; 0x7E1 configuration end: data[0..3] the text's
//         length, data[4..7] its FNV-1a 32-bit hash (little-endian): a gap or reordering is detected.
//   0x7F1 receive stamp (lockstep): twin -> controller, just before a forwarded frame; data: the
//         simulated time at which the virtual bus delivered it (the controller's receive time stamp).
// None of these is put on the twin's virtual CAN bus: the twin handles them at the link.
#pragma once
#include <cstdint>
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "protocol/can_frame.h"

namespace exotwin::link {

constexpr uint16_t kIdNmt = 0x000;
constexpr uint16_t kIdSync = 0x080;
constexpr uint16_t kIdReady = 0x701;
constexpr uint16_t kIdTelemetryBase = 0x780;
constexpr int kTelemetryValues = 16;
constexpr uint16_t kIdConfigRequest = 0x702;
constexpr uint16_t kIdConfigData = 0x7E0;
constexpr uint16_t kIdConfigEnd = 0x7E1;
constexpr uint16_t kIdCycleDone = 0x7F0;
constexpr uint16_t kIdRxStamp = 0x7F1;
constexpr uint8_t kNmtStart = 0x01;
constexpr uint8_t kNmtStop = 0x02;
constexpr uint8_t kStateOperational = 0x05;

// The telemetry values (ControllerTelemetry of controller/exo_controller.h).
enum TelemetryIndex {
  kTelEstQHip = 0, kTelEstQKnee, kTelTauSensorHip, kTelTauSensorKnee, kTelTauCmdHip, kTelTauCmdKnee,
  kTelRefQHip, kTelRefQKnee, kTelState, kTelEmg0,  // kTelEmg0 .. kTelEmg0 + 4: the five EMG channels
  kTelCount = kTelEmg0 + 5,
};

// The telemetry values of the HAL-3 knee loop (HalTelemetry of controller/hal_loop.h), same identifiers.
enum HalTelemetryIndex {
  kHalTelTh = 0, kHalTelStrain, kHalTelThd, kHalTelTauCmd, kHalTelEe, kHalTelEf, kHalTelMuHat, kHalTelD,
  kHalTelK, kHalTelTauMu, kHalTelTauZeta, kHalTelTauC, kHalTelIHat, kHalTelEmgGaps, kHalTelEnabled,
  kHalTelCount,
};
static_assert(kTelCount <= kTelemetryValues && kHalTelCount <= kTelemetryValues, "telemetry beyond 0x78F");

// A DLC 8 frame carrying v.
inline CanFrame DoubleFrame(uint16_t id, double v) {
  CanFrame f;
  f.id = id;
  f.dlc = 8;
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  for (int i = 0; i < 8; ++i) f.data[i] = static_cast<uint8_t>(bits >> (8 * i));
  return f;
}

// The double of a DLC 8 frame (false when f is not DLC 8).
inline bool FrameDouble(const CanFrame& f, double* v) {
  if (f.dlc != 8 || f.error) return false;
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= static_cast<uint64_t>(f.data[i]) << (8 * i);
  std::memcpy(v, &bits, 8);
  return true;
}

// An NMT frame; `sequence` numbers the starts of a session (kNmtStart).
inline CanFrame NmtFrame(uint8_t command, int trial, uint16_t sequence = 0) {
  CanFrame f;
  f.id = kIdNmt;
  f.dlc = 5;
  f.data[0] = command;
  f.data[2] = static_cast<uint8_t>(trial);
  f.data[3] = static_cast<uint8_t>(sequence), f.data[4] = static_cast<uint8_t>(sequence >> 8);
  return f;
}

// The sequence number of an NMT start, a ready frame or a configuration request (0 when absent).
inline uint16_t StartSequence(const CanFrame& f) {
  const int at = f.id == kIdNmt ? 3 : 2;
  return f.dlc >= at + 2 ? static_cast<uint16_t>(f.data[at] | (f.data[at + 1] << 8)) : 0;
}

// The answer to the NMT start `sequence` of trial `trial`.
inline CanFrame ReadyFrame(int trial, uint16_t sequence = 0) {
  CanFrame f;
  f.id = kIdReady;
  f.dlc = 4;
  f.data[0] = kStateOperational;
  f.data[1] = static_cast<uint8_t>(trial);
  f.data[2] = static_cast<uint8_t>(sequence), f.data[3] = static_cast<uint8_t>(sequence >> 8);
  return f;
}

// True for the link's own identifiers (never forwarded to the virtual bus).
inline bool IsLinkFrameId(uint16_t id) {
  return id == kIdNmt || id == kIdSync || id == kIdReady || id == kIdCycleDone || id == kIdRxStamp ||
         id == kIdConfigRequest || id == kIdConfigData || id == kIdConfigEnd ||
         (id >= kIdTelemetryBase && id < kIdTelemetryBase + kTelemetryValues);
}

// FNV-1a, 32 bits, of a configuration text (the check of its download).
inline uint32_t ConfigHash(const std::string& text) {
  uint32_t h = 2166136261u;
  for (unsigned char c : text) h = (h ^ c) * 16777619u;
  return h;
}

// The frames that carry `text` to the controller: data frames of 8 bytes (the last 1..8), then the end.
inline std::vector<CanFrame> ConfigFrames(const std::string& text) {
  std::vector<CanFrame> out;
  for (size_t i = 0; i < text.size(); i += 8) {
    CanFrame f;
    f.id = kIdConfigData;
    f.dlc = static_cast<uint8_t>(std::min<size_t>(8, text.size() - i));
    std::memcpy(f.data.data(), text.data() + i, f.dlc);
    out.push_back(f);
  }
  CanFrame e;
  e.id = kIdConfigEnd;
  e.dlc = 8;
  const uint32_t n = static_cast<uint32_t>(text.size()), h = ConfigHash(text);
  for (int i = 0; i < 4; ++i) e.data[i] = static_cast<uint8_t>(n >> (8 * i)), e.data[4 + i] = static_cast<uint8_t>(h >> (8 * i));
  out.push_back(e);
  return out;
}

// Length and hash of a configuration end frame (false when not DLC 8).
inline bool ConfigEnd(const CanFrame& f, uint32_t* length, uint32_t* hash) {
  if (f.dlc != 8) return false;
  *length = *hash = 0;
  for (int i = 0; i < 4; ++i) *length |= uint32_t{f.data[i]} << (8 * i), *hash |= uint32_t{f.data[4 + i]} << (8 * i);
  return true;
}

}  // namespace exotwin::link
