// A small reader of Vector DBC files: the BO_ (message) and SG_ (signal) lines, enough to decode and
// encode the signals of classic CAN frames. Other sections (VERSION, NS_, BU_, CM_, VAL_, BA_...)
// are skipped. Malformed BO_/SG_ lines throw InputError naming the file and line.
#pragma once
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "protocol/can_frame.h"

namespace exotwin {

struct DbcSignal {
  std::string name;
  int start_bit = 0;          // DBC start bit: LSB position (Intel) or MSB position (Motorola)
  int length = 1;             // bits, 1..64
  bool little_endian = true;  // @1 Intel; @0 Motorola
  bool is_signed = false;     // '-' two's complement; '+' unsigned
  double factor = 1, offset = 0;
  double minimum = 0, maximum = 0;
  std::string unit;
  std::vector<std::string> receivers;

  // The raw field, sign-extended when signed (precondition: the signal fits in 8 bytes).
  int64_t RawValue(const CanFrame& f) const;
  // Physical value = raw * factor + offset.
  double Decode(const CanFrame& f) const;
  // Writes round((phys - offset) / factor), wrapped to the field width, into f's data bytes.
  void Encode(double phys, CanFrame* f) const;
};

struct DbcMessage {
  uint32_t id = 0;
  std::string name;
  int dlc = 0;
  std::string sender;
  std::vector<DbcSignal> signals;
  // The signal of that name or nullptr.
  const DbcSignal* Find(const std::string& signal) const;
};

struct DbcDatabase {
  std::vector<DbcMessage> messages;
  // The message with that identifier or name, or nullptr.
  const DbcMessage* FindById(uint32_t id) const;
  const DbcMessage* FindByName(const std::string& name) const;
};

// Parses DBC text; source names the input in error messages. Throws InputError.
DbcDatabase ParseDbc(std::istream& in, const std::string& source);
// Reads and parses a DBC file. Throws InputError (unreadable file, malformed line).
DbcDatabase LoadDbc(const std::string& path);

}  // namespace exotwin
