#include "protocol/messages.h"

#include <cmath>

namespace exotwin::msg {
namespace {

// round(v / scale) saturated to [lo, hi]; NaN -> 0.
int64_t Quantize(double v, double scale, int64_t lo, int64_t hi) {
  if (std::isnan(v)) return 0;
  const double r = std::round(v / scale);
  if (r <= static_cast<double>(lo)) return lo;
  if (r >= static_cast<double>(hi)) return hi;
  return static_cast<int64_t>(r);
}

// Little-endian byte-aligned writers/readers.
void PutLe(CanFrame* f, int byte, int nbytes, uint64_t raw) {
  for (int i = 0; i < nbytes; ++i) f->data[byte + i] = static_cast<uint8_t>(raw >> (8 * i));
}
uint64_t GetLe(const CanFrame& f, int byte, int nbytes) {
  uint64_t v = 0;
  for (int i = 0; i < nbytes; ++i) v |= static_cast<uint64_t>(f.data[byte + i]) << (8 * i);
  return v;
}
int16_t GetI16(const CanFrame& f, int byte) { return static_cast<int16_t>(GetLe(f, byte, 2)); }
int32_t GetI32(const CanFrame& f, int byte) { return static_cast<int32_t>(GetLe(f, byte, 4)); }

CanFrame Make(uint16_t id, uint8_t dlc) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  return f;
}
bool Is(const CanFrame& f, uint16_t id, uint8_t dlc) { return !f.error && f.id == id && f.dlc == dlc; }

constexpr int64_t kI16Min = -32768, kI16Max = 32767;

CanFrame EncodeCommand(uint16_t id, double torque, uint8_t counter, bool enable) {
  CanFrame f = Make(id, 4);
  PutLe(&f, 0, 2, static_cast<uint64_t>(Quantize(torque, kCommandTorqueScale, kI16Min, kI16Max)));
  f.data[2] = counter;
  f.data[3] = enable ? 1 : 0;
  return f;
}

}  // namespace

const char* JointName(Joint j) { return j == Joint::kHip ? "hip" : "knee"; }

CanFrame Encode(const ControllerHeartbeat& m) {
  CanFrame f = Make(kIdControllerHeartbeat, 5);
  f.data[0] = m.state;
  PutLe(&f, 1, 2, m.fault_mask);
  f.data[3] = m.first_fault;
  f.data[4] = m.counter;
  return f;
}

bool Decode(const CanFrame& f, ControllerHeartbeat* out) {
  if (!Is(f, kIdControllerHeartbeat, 5)) return false;
  out->state = f.data[0];
  out->fault_mask = static_cast<uint16_t>(GetLe(f, 1, 2));
  out->first_fault = f.data[3];
  out->counter = f.data[4];
  return true;
}

CanFrame Encode(const JointCommand& m) { return EncodeCommand(JointCommandId(m.joint), m.torque, m.counter, m.enable); }

bool Decode(const CanFrame& f, JointCommand* out) {
  Joint j;
  if (Is(f, kIdJointCommandHip, 4)) j = Joint::kHip;
  else if (Is(f, kIdJointCommandKnee, 4)) j = Joint::kKnee;
  else return false;
  out->joint = j;
  out->torque = GetI16(f, 0) * kCommandTorqueScale;
  out->counter = f.data[2];
  out->enable = (f.data[3] & 1) != 0;
  return true;
}

CanFrame Encode(const JointStatus& m) {
  CanFrame f = Make(JointStatusId(m.joint), 8);
  PutLe(&f, 0, 4, static_cast<uint64_t>(Quantize(m.angle, kEncoderAngleScale, INT32_MIN, INT32_MAX)));
  PutLe(&f, 4, 2, static_cast<uint64_t>(Quantize(m.torque, kSensorTorqueScale, kI16Min, kI16Max)));
  f.data[6] = m.flags;
  f.data[7] = m.counter;
  return f;
}

bool Decode(const CanFrame& f, JointStatus* out) {
  Joint j;
  if (Is(f, kIdJointStatusHip, 8)) j = Joint::kHip;
  else if (Is(f, kIdJointStatusKnee, 8)) j = Joint::kKnee;
  else return false;
  out->joint = j;
  out->angle = GetI32(f, 0) * kEncoderAngleScale;
  out->torque = GetI16(f, 4) * kSensorTorqueScale;
  out->flags = f.data[6];
  out->counter = f.data[7];
  return true;
}

CanFrame Encode(const HalKneeCommand& m) { return EncodeCommand(kIdHalKneeCommand, m.torque, m.counter, m.enable); }

bool Decode(const CanFrame& f, HalKneeCommand* out) {
  if (!Is(f, kIdHalKneeCommand, 4)) return false;
  out->torque = GetI16(f, 0) * kCommandTorqueScale;
  out->counter = f.data[2];
  out->enable = (f.data[3] & 1) != 0;
  return true;
}

CanFrame Encode(const HalKneeStatus& m) {
  CanFrame f = Make(kIdHalKneeStatus, 6);
  PutLe(&f, 0, 2, static_cast<uint64_t>(Quantize(m.angle, kHalAngleScale, kI16Min, kI16Max)));
  PutLe(&f, 2, 2, static_cast<uint64_t>(Quantize(m.torque, kHalTorqueScale, kI16Min, kI16Max)));
  f.data[4] = m.flags;
  f.data[5] = m.counter;
  return f;
}

bool Decode(const CanFrame& f, HalKneeStatus* out) {
  if (!Is(f, kIdHalKneeStatus, 6)) return false;
  out->angle = GetI16(f, 0) * kHalAngleScale;
  out->torque = GetI16(f, 2) * kHalTorqueScale;
  out->flags = f.data[4];
  out->counter = f.data[5];
  return true;
}

// EMG: channel k occupies bits [12k, 12k + 12) of the little-endian 64-bit payload, the counter
// bits [60, 64).
CanFrame Encode(const EmgSamples& m) {
  CanFrame f = Make(kIdEmgSamples, 8);
  uint64_t word = 0;
  for (int k = 0; k < kEmgChannels; ++k) {
    const int64_t raw = Quantize(m.volts[k], kEmgScale, -2048, 2047);
    word |= (static_cast<uint64_t>(raw) & 0xFFFu) << (12 * k);
  }
  word |= (static_cast<uint64_t>(m.counter) & 0xFu) << 60;
  PutLe(&f, 0, 8, word);
  return f;
}

bool Decode(const CanFrame& f, EmgSamples* out) {
  if (!Is(f, kIdEmgSamples, 8)) return false;
  const uint64_t word = GetLe(f, 0, 8);
  for (int k = 0; k < kEmgChannels; ++k) {
    int32_t raw = static_cast<int32_t>((word >> (12 * k)) & 0xFFFu);
    if (raw >= 2048) raw -= 4096;
    out->volts[k] = raw * kEmgScale;
  }
  out->counter = static_cast<uint8_t>(word >> 60);
  return true;
}

}  // namespace exotwin::msg
