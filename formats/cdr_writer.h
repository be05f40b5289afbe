// ROS 2 messages encoded as CDR (OMG CDR, little-endian, as rmw's Fast CDR serializes them): the
// encapsulation header 00 01 00 00 (CDR_LE), then the fields in order, each primitive aligned to its
// size counted from the end of the header; a string is uint32 length (with its NUL) + bytes + NUL; a
// sequence is uint32 count + elements. The messages exotwin writes into bags (runner/run_bag.h) and
// their definitions as `ros2 bag` stores them in a ros2msg schema: the type's .msg text, then each
// dependency after a line of 80 '=' and "MSG: package/Type".
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace exotwin::cdr {

class CdrWriter {
 public:
  CdrWriter() { Reset(); }
  // Starts a new message: the buffer holds the encapsulation header alone.
  void Reset();
  void Int32(int32_t v) { Primitive(&v, 4); }
  void Uint32(uint32_t v) { Primitive(&v, 4); }
  void Float64(double v) { Primitive(&v, 8); }
  void String(const std::string& v);
  // Returns the offset in bytes() of the first element (after its alignment).
  size_t Float64Sequence(const double* v, size_t n);
  void StringSequence(const std::vector<std::string>& v);
  const std::vector<uint8_t>& bytes() const { return buf_; }

 private:
  void Align(size_t n);
  void Primitive(const void* v, size_t n);  // aligned, little-endian (the host's order: checked at build)
  std::vector<uint8_t> buf_;
};

// builtin_interfaces/msg/Time of a time in ns: sec = floor(ns / 1e9), nanosec the rest.
void Time(CdrWriter& w, int64_t ns);

// Where the fields of a message encoded once lie in its bytes, so that a message of the same shape
// (the same names, labels and counts) is the same bytes with these overwritten (PatchTime,
// PatchFloat64s): offsets in bytes(), 0 for an empty array.
struct JointStateLayout {
  size_t stamp = 0, position = 0, velocity = 0, effort = 0;
};

// sensor_msgs/msg/JointState: header (stamp, frame_id), name, position, velocity, effort. Each array of
// n values (`velocity` or `effort` null: an empty array, as the message allows).
JointStateLayout JointState(CdrWriter& w, int64_t stamp_ns, const std::string& frame_id,
                            const std::vector<std::string>& names, const double* position, const double* velocity,
                            const double* effort, size_t n);

// std_msgs/msg/Float64MultiArray of n values: layout one dimension {label, size n, stride n}, data_offset 0.
// Returns the offset of data[0] (0 when n = 0).
size_t Float64MultiArray(CdrWriter& w, const std::string& label, const double* data, size_t n);

// Overwrite, in a message's bytes, a Time at `at` (as Time writes it) and n float64 at `at`.
void PatchTime(uint8_t* at, int64_t ns);
void PatchFloat64s(uint8_t* at, const double* v, size_t n);

// The type names and ros2msg schema texts of the messages above.
extern const char* const kJointStateType;         // "sensor_msgs/msg/JointState"
extern const char* const kFloat64MultiArrayType;  // "std_msgs/msg/Float64MultiArray"
const std::string& JointStateDefinition();
const std::string& Float64MultiArrayDefinition();

}  // namespace exotwin::cdr
