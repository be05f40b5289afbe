// The frames of the twin-controller link beyond the device messages of protocol/messages.h
// (DESIGN.md "The CAN transport between processes"). Values are IEEE-754 doubles, little-endian,
// DLC 8, so the simulated times and the controller's telemetry cross the process boundary exactly.
//   0x000 NMT (CANopen): twin -> controller. data[0] 0x01 start (data[2] the trial, 0-based: the
//         controller starts a fresh control loop), 0x02 stop (the run is over: the controller exits).
//   0x080 SYNC (CANopen COB-ID): twin -> controller, once per controller period; data: the tick's
//         simulated time t (s). The controller ticks at t on the frames received before it.
//   0x701 boot-up / ready: controller -> twin, answer to an NMT start; data[0] 0x05, data[1] the trial.
//   0x780 + i telemetry: controller -> twin after each tick, i = TelemetryIndex (the value logged).
//   0x7F0 cycle done: controller -> twin, last frame of a tick; data: the SYNC's t echoed.
//   0x7F1 receive stamp (lockstep): twin -> controller, just before a forwarded frame; data: the
//         simulated time at which the virtual bus delivered it (the controller's receive time stamp).
// None of these is put on the twin's virtual CAN bus: the twin handles them at the link.
#pragma once
#include <cstdint>
#include <cstring>

#include "protocol/can_frame.h"

namespace exotwin::link {

constexpr uint16_t kIdNmt = 0x000;
constexpr uint16_t kIdSync = 0x080;
constexpr uint16_t kIdReady = 0x701;
constexpr uint16_t kIdTelemetryBase = 0x780;
constexpr int kTelemetryValues = 16;
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

inline CanFrame NmtFrame(uint8_t command, int trial) {
  CanFrame f;
  f.id = kIdNmt;
  f.dlc = 3;
  f.data[0] = command;
  f.data[2] = static_cast<uint8_t>(trial);
  return f;
}

inline CanFrame ReadyFrame(int trial) {
  CanFrame f;
  f.id = kIdReady;
  f.dlc = 2;
  f.data[0] = kStateOperational;
  f.data[1] = static_cast<uint8_t>(trial);
  return f;
}

// True for the link's own identifiers (never forwarded to the virtual bus).
inline bool IsLinkFrameId(uint16_t id) {
  return id == kIdNmt || id == kIdSync || id == kIdReady || id == kIdCycleDone || id == kIdRxStamp ||
         (id >= kIdTelemetryBase && id < kIdTelemetryBase + kTelemetryValues);
}

}  // namespace exotwin::link
