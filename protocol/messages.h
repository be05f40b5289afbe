// The exotwin CAN frame protocol (classic CAN 2.0A, 1 Mbit/s, little-endian/Intel signals) between
// the controller, the EXOwheel joint modules (hip, knee), the HAL-3 knee unit and the EMG amplifier.
// protocol/exotwin.dbc describes every signal (bits, scale, offset, unit); tests/protocol/dbc_agreement
// checks that this codec and the DBC agree. Lower IDs win arbitration, so IDs follow criticality:
// heartbeat/faults < torque commands < sensor status < EMG.
// Encoding saturates each value to its field's range and encodes NaN as 0 (plain functions, no
// exceptions); decoding returns false when the frame's ID or DLC is not that message's.
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "protocol/can_frame.h"

namespace exotwin::msg {

enum class Joint : uint8_t { kHip = 0, kKnee = 1 };

// Identifiers (11-bit).
constexpr uint16_t kIdControllerHeartbeat = 0x010;  // controller -> all, 100 Hz and on a fault, DLC 5
constexpr uint16_t kIdJointCommandBase = 0x100;     // controller -> joint module, + joint, DLC 4
constexpr uint16_t kIdJointCommandHip = 0x100;
constexpr uint16_t kIdJointCommandKnee = 0x101;
constexpr uint16_t kIdHalKneeCommand = 0x110;       // controller -> HAL-3 knee, DLC 4
constexpr uint16_t kIdJointStatusBase = 0x180;      // joint module -> controller, + joint, DLC 8
constexpr uint16_t kIdJointStatusHip = 0x180;
constexpr uint16_t kIdJointStatusKnee = 0x181;
constexpr uint16_t kIdHalKneeStatus = 0x190;        // HAL-3 knee -> controller, DLC 6
constexpr uint16_t kIdEmgSamples = 0x200;           // EMG amplifier -> controller, 1 kHz, DLC 8

// Scalings (physical value = raw * scale).
constexpr double kCommandTorqueScale = 0.01;   // N m per LSB, int16 (+-327.67 N m)
constexpr double kEncoderAngleScale = 1e-6;    // rad per LSB, int32
constexpr double kSensorTorqueScale = 0.015;   // N m per LSB, int16 (= the sensor's resolution)
constexpr double kHalAngleScale = 1e-4;        // rad per LSB, int16 (+-3.2767 rad)
constexpr double kHalTorqueScale = 0.01;       // N m per LSB, int16
constexpr double kEmgScale = 5.0 / 2048.0;     // V per LSB, int12 (-5 .. +4.99756 V after gain 1000)
constexpr int kEmgChannels = 5;                // GMAX, VM, RF, ST, GAS (DESIGN.md order)

// Joint-module and HAL status bits (JointStatus::flags, HalKneeStatus::flags).
constexpr uint8_t kStatusEnabled = 1u << 0;           // power stage enabled
constexpr uint8_t kStatusWatchdog = 1u << 1;          // command watchdog tripped, torque cut
constexpr uint8_t kStatusTorqueSensorFault = 1u << 2; // torque reading invalid (NaN, stuck)
constexpr uint8_t kStatusEncoderFault = 1u << 3;      // angle reading invalid
constexpr uint8_t kStatusTorqueLimit = 1u << 4;       // command saturated at the driver limit
constexpr uint8_t kStatusDriverFault = 1u << 5;       // over-current / over-temperature

// Controller heartbeat: state and latched faults, the modules' watchdog feed.
struct ControllerHeartbeat {
  uint8_t state = 0;          // controller SafetyState: 0 running, 1 safe damping, 2 safe torque off
  uint16_t fault_mask = 0;    // bit (1 << FaultCode) of controller/safety_supervisor.h
  uint8_t first_fault = 0;    // FaultCode of the first latched fault (0 none)
  uint8_t counter = 0;        // increments every frame (wraps at 256)
};

// Torque command to a joint module (and, same layout, to the HAL-3 knee).
struct JointCommand {
  Joint joint = Joint::kHip;
  double torque = 0;          // N m, motor torque command, int16 x 0.01 N m
  uint8_t counter = 0;        // sequence counter (wraps at 256)
  bool enable = false;        // false: module applies zero torque
};

// Joint-module measurement frame.
struct JointStatus {
  Joint joint = Joint::kHip;
  double angle = 0;           // rad, encoder angle, int32 x 1e-6 rad
  double torque = 0;          // N m, torque-sensor reading tau_S, int16 x 0.015 N m
  uint8_t flags = 0;          // kStatus* bits
  uint8_t counter = 0;        // sequence counter (wraps at 256)
};

struct HalKneeCommand {
  double torque = 0;          // N m, assist torque command, int16 x 0.01 N m
  uint8_t counter = 0;
  bool enable = false;
};

struct HalKneeStatus {
  double angle = 0;           // rad, potentiometer knee angle, int16 x 1e-4 rad
  double torque = 0;          // N m, strain-gauge torque, int16 x 0.01 N m
  uint8_t flags = 0;          // kStatus* bits
  uint8_t counter = 0;
};

// One 1 kHz sample of the five EMG channels after the amplifier (gain 1000, range +-5 V).
struct EmgSamples {
  std::array<double, kEmgChannels> volts{};  // V, int12 x 5/2048 V each
  uint8_t counter = 0;                        // 4-bit sample counter (wraps at 16)
};

CanFrame Encode(const ControllerHeartbeat& m);  // ID 0x010
CanFrame Encode(const JointCommand& m);         // ID 0x100 + joint
CanFrame Encode(const JointStatus& m);          // ID 0x180 + joint
CanFrame Encode(const HalKneeCommand& m);       // ID 0x110
CanFrame Encode(const HalKneeStatus& m);        // ID 0x190
CanFrame Encode(const EmgSamples& m);           // ID 0x200

// Decoders: true and *out filled when the frame is that message (ID and DLC match, not an error frame).
bool Decode(const CanFrame& f, ControllerHeartbeat* out);
bool Decode(const CanFrame& f, JointCommand* out);
bool Decode(const CanFrame& f, JointStatus* out);
bool Decode(const CanFrame& f, HalKneeCommand* out);
bool Decode(const CanFrame& f, HalKneeStatus* out);
bool Decode(const CanFrame& f, EmgSamples* out);

// ID helpers.
inline uint16_t JointCommandId(Joint j) { return static_cast<uint16_t>(kIdJointCommandBase + static_cast<int>(j)); }
inline uint16_t JointStatusId(Joint j) { return static_cast<uint16_t>(kIdJointStatusBase + static_cast<int>(j)); }
// "hip" or "knee".
const char* JointName(Joint j);

}  // namespace exotwin::msg
