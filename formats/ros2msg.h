// ROS 2 messages in a bag (DESIGN.md "ROS 2 bags (MCAP) in and out"): the message definitions of a
// `ros2msg` schema (docs.ros.org, "Interfaces"; mcap.dev/spec/registry#ros2msg), the CDR decoding of
// a message by them (OMG CDR, XCDR version 1, as ROS 2's rmw implementations write it), and JSON
// messages (`json` encoding). Decoding is generic: a message becomes a tree of named fields that a
// field path (`header.stamp`, `position[hip]`, `items[2].value`) selects from; no message type is
// special.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace exotwin {

// A decoded message, or one of its fields.
struct MsgValue {
  enum Kind { kNull, kBool, kInt, kUint, kFloat, kString, kArray, kStruct };
  Kind kind = kNull;
  int64_t i = 0;   // kInt; kBool: 0 or 1
  uint64_t u = 0;  // kUint
  double f = 0;    // kFloat
  std::string s;   // kString
  std::vector<MsgValue> items;                             // kArray
  std::vector<std::pair<std::string, MsgValue>> fields;   // kStruct, in definition order

  bool IsNumber() const { return kind == kBool || kind == kInt || kind == kUint || kind == kFloat; }
  double Number() const;  // precondition: IsNumber()
  // The field `name` of a struct; nullptr if absent (or not a struct).
  const MsgValue* Field(const std::string& name) const;
  // "field1, field2, ..." of a struct, for messages.
  std::string FieldNames() const;
};

// One field of a message definition.
struct MsgField {
  enum Array { kScalar, kFixed, kBounded, kSequence };  // T, T[N], T[<=N], T[]
  std::string name;
  std::string type;       // a builtin ("float64", "string", ...) or a message's full name ("pkg/Type")
  int message = -1;       // a message type: its index in Ros2MsgSchema::definitions()
  Array array = kScalar;
  uint64_t array_size = 0;    // kFixed: N; kBounded: the bound
  uint64_t string_bound = 0;  // string<=N: N (0: unbounded)
};

struct MsgDefinition {
  std::string name;  // "pkg/Type" ("pkg/msg/Type" as given is normalized so)
  std::vector<MsgField> fields;  // constants left out
};

// The message definitions of a ros2msg schema text: the main definition, then dependent ones, each
// after a line of '=' and a line "MSG: pkg/Type". Lines: "TYPE NAME [DEFAULT]"; "TYPE NAME=VALUE" is
// a constant (skipped); '#' starts a comment. Types: bool, byte, char, int8 .. uint64, float32,
// float64, string, string<=N, wstring (refused: its encoding is implementation-defined), a message
// type "pkg/Type", "pkg/msg/Type" or "Type" (its own package's; Header is std_msgs/Header), the ROS 1
// builtins time and duration (builtin_interfaces/Time and Duration); each optionally T[N], T[<=N] or
// T[]. builtin_interfaces/Time and Duration are supplied when the text lacks their MSG blocks.
class Ros2MsgSchema {
 public:
  // `name`: the schema's name (the main definition's type); `source` names the schema in messages
  // ("bag.mcap: schema sensor_msgs/msg/JointState"). Throws InputError naming the source, the line and
  // what was expected for: a malformed line, an unknown type, a type with no definition, a
  // definition that contains itself.
  Ros2MsgSchema(const std::string& name, const std::string& text, const std::string& source);

  const std::vector<MsgDefinition>& definitions() const { return defs_; }  // [0]: the main one

  // Decodes one message: the 4-byte encapsulation header (0x00 0x01: CDR little-endian, 0x00 0x00:
  // big-endian), then the fields in order, each primitive aligned to its size (8 at most) counted
  // from after the header; strings as uint32 length (the NUL included) and the bytes; sequences as
  // uint32 count and the elements; fixed arrays without a count; an empty definition as one uint8.
  // Throws InputError naming `where` and the field for: another encapsulation, bytes ending inside a
  // field, a sequence or string beyond its bound.
  MsgValue Decode(const std::string& bytes, const std::string& where) const;

 private:
  std::vector<MsgDefinition> defs_;
};

// A `json`-encoded message (mcap.dev/spec/registry#json): a JSON object, as a tree. Throws InputError
// naming `where` for text that is not a JSON object.
MsgValue DecodeJsonMessage(const std::string& bytes, const std::string& where);

// A field path: "a.b[2].c", "position[hip]" (an index by name: NAME's index in the `name` array beside
// the indexed one, as in sensor_msgs/JointState).
struct FieldPath {
  struct Step {
    std::string field;
    bool indexed = false;
    bool by_name = false;   // [NAME]
    uint64_t index = 0;     // [N]
    std::string key;        // [NAME]
  };
  std::vector<Step> steps;
  std::string text;
};

// Parses a field path; throws InputError("<context>: ...") for an empty step, an unclosed or empty
// bracket.
FieldPath ParseFieldPath(const std::string& text, const std::string& context);

// The value at `path` in `msg`; throws InputError naming `where` (the message) and the path for a
// field the message lacks (its fields listed), an index beyond the array, a NAME absent from the
// sibling `name` array (its names listed).
const MsgValue& ResolveField(const MsgValue& msg, const FieldPath& path, const std::string& where);

}  // namespace exotwin
