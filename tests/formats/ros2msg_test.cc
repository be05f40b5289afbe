// ROS 2 message definitions and CDR: messages laid out by hand from the CDR rules (alignment counted
// from after the 4-byte encapsulation header, 8 at most; strings with their NUL; sequences counted;
// fixed arrays not; an empty message one byte) in both byte orders decode to the values put in;
// definitions with constants, defaults, bounds, nested and relative types parse; malformed ones and
// malformed messages throw InputError naming the schema's line or the field. Field paths select by
// index and by name. (The round trip against Foxglove's writer: mcap_reader_test.cc.)
#include "formats/ros2msg.h"

#include <gtest/gtest.h>

#include <cstring>

#include "core/error.h"
#include "tests/expect_input_error.h"

namespace exotwin {
namespace {

using testing::ExpectInputError;

// A CDR message built by hand: little- or big-endian, with the alignment rule of the encoding.
class Cdr {
 public:
  explicit Cdr(bool little = true) : little_(little) { b_ = std::string("\0", 1) + (little ? '\1' : '\0') + std::string(2, '\0'); }
  Cdr& Uint(uint64_t v, int size) {
    while ((b_.size() - 4) % size) b_ += '\xEE';  // padding bytes: any value
    for (int k = 0; k < size; ++k) b_ += static_cast<char>(v >> (8 * (little_ ? k : size - 1 - k)));
    return *this;
  }
  Cdr& F64(double x) {
    uint64_t u;
    std::memcpy(&u, &x, 8);
    return Uint(u, 8);
  }
  Cdr& F32(float x) {
    uint32_t u;
    std::memcpy(&u, &x, 4);
    return Uint(u, 4);
  }
  Cdr& Str(const std::string& s) {
    Uint(s.size() + 1, 4);
    b_ += s;
    b_ += '\0';
    return *this;
  }
  const std::string& bytes() const { return b_; }

 private:
  bool little_;
  std::string b_;
};

const MsgValue& At(const MsgValue& m, const std::string& path) { return ResolveField(m, ParseFieldPath(path, "test"), "test"); }

constexpr char kSample[] =
    "# comment line\n"
    "int8 A_CONSTANT = -3   # constants are not fields\n"
    "string S_CONSTANT=\"x # y\"\n"
    "int8 small\n"
    "float64 wide          # after one int8: 7 bytes of padding\n"
    "string<=10 label\n"
    "uint16[3] fixed\n"
    "Item[<=2] items\n"
    "bool flag true        # a default value\n"
    "float32 gain\n"
    "time stamp\n"
    "int64 big\n"
    "Empty nothing\n"
    "================================================================================\n"
    "MSG: test_pkg/Item\n"
    "string name\n"
    "int32[] counts\n"
    "================================================================================\n"
    "MSG: test_pkg/msg/Empty\n";

Cdr SampleBytes(bool little) {
  Cdr c(little);
  c.Uint(static_cast<uint8_t>(-5), 1).F64(-2.75).Str("knee").Uint(1, 2).Uint(65535, 2).Uint(3, 2);
  c.Uint(2, 4).Str("a").Uint(2, 4).Uint(static_cast<uint32_t>(-7), 4).Uint(9, 4).Str("").Uint(0, 4);
  c.Uint(1, 1).F32(0.5f).Uint(static_cast<uint32_t>(-1), 4).Uint(999999999, 4).Uint(static_cast<uint64_t>(-(1LL << 60)), 8);
  c.Uint(0, 1);
  return c;
}

TEST(Ros2Msg, ADefinitionWithEveryKindOfFieldDecodesBothByteOrders) {
  const Ros2MsgSchema s("test_pkg/msg/Sample", kSample, "sample");
  ASSERT_EQ(s.definitions().size(), 5u);  // Sample, Item, Empty, + Time and Duration supplied
  EXPECT_EQ(s.definitions()[0].name, "test_pkg/Sample");
  EXPECT_EQ(s.definitions()[0].fields.size(), 10u);
  for (bool little : {true, false}) {
    SCOPED_TRACE(little ? "little-endian" : "big-endian");
    const MsgValue m = s.Decode(SampleBytes(little).bytes(), "msg");
    EXPECT_EQ(At(m, "small").i, -5);
    EXPECT_EQ(At(m, "wide").f, -2.75);
    EXPECT_EQ(At(m, "label").s, "knee");
    EXPECT_EQ(At(m, "fixed[1]").u, 65535u);
    EXPECT_EQ(At(m, "fixed").items.size(), 3u);
    EXPECT_EQ(At(m, "items[0].name").s, "a");
    EXPECT_EQ(At(m, "items[0].counts[0]").i, -7);
    EXPECT_EQ(At(m, "items[0].counts[1]").i, 9);
    EXPECT_EQ(At(m, "items[1].name").s, "");
    EXPECT_EQ(At(m, "items[1].counts").items.size(), 0u);
    EXPECT_EQ(At(m, "flag").kind, MsgValue::kBool);
    EXPECT_EQ(At(m, "flag").Number(), 1.0);
    EXPECT_EQ(At(m, "gain").f, 0.5);
    EXPECT_EQ(At(m, "stamp.sec").i, -1);
    EXPECT_EQ(At(m, "stamp.nanosec").u, 999999999u);
    EXPECT_EQ(At(m, "big").i, -(1LL << 60));
    EXPECT_EQ(At(m, "nothing").fields.size(), 0u);
  }
}

TEST(Ros2Msg, TypesResolveByPackageAndHeaderAndTimeAreSupplied) {
  const Ros2MsgSchema s("sensor_msgs/msg/Probe",
                        "Header header\nduration span\nbuiltin_interfaces/Time t\n"
                        "====\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n",
                        "probe");
  Cdr c;
  c.Uint(7, 4).Uint(8, 4).Str("f").Uint(static_cast<uint32_t>(-2), 4).Uint(5, 4).Uint(1, 4).Uint(2, 4);
  const MsgValue m = s.Decode(c.bytes(), "msg");
  EXPECT_EQ(At(m, "header.stamp.sec").i, 7);
  EXPECT_EQ(At(m, "header.frame_id").s, "f");
  EXPECT_EQ(At(m, "span.sec").i, -2);
  EXPECT_EQ(At(m, "t.nanosec").u, 2u);
}

TEST(Ros2Msg, BadDefinitionsNameTheLine) {
  ExpectInputError([] { Ros2MsgSchema("p/T", "float64 x\nfloat65 y\n", "s"); },
                   {"s: line 2 (p/T): type 'float65' has no definition"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "float64\n", "s"); }, {"s: line 1", "expected 'TYPE NAME'"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "float64 2x\n", "s"); }, {"s: line 1", "expected a field name"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "float64[x] a\n", "s"); }, {"s: line 1", "expected an array size"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "string<=0 a\n", "s"); }, {"s: line 1", "string<=N"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "int8[0] a\n", "s"); }, {"s: line 1", "expected an array size N > 0"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "wstring a\n", "s"); }, {"s: line 1", "wstring is not decoded"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "int8 a\n=====\nint8 b\n", "s"); }, {"s: line 3", "expected 'MSG: pkg/Type'"});
  ExpectInputError([] { Ros2MsgSchema("p/T", "U u\n====\nMSG: p/U\nT t\n", "s"); }, {"s: p/U contains itself", "'t'"});
  ExpectInputError([] { Ros2MsgSchema("p/T", std::string("int8 a\xC1\n"), "s"); }, {"s: invalid UTF-8"});
}

TEST(Ros2Msg, MalformedMessagesNameTheField) {
  const Ros2MsgSchema s("p/T", "float64 x\nstring<=3 name\nint32[<=2] v\n", "s");
  ExpectInputError([&] { s.Decode(std::string("\0\1", 2), "m"); }, {"m: 2 bytes, expected a CDR message"});
  ExpectInputError([&] { s.Decode(std::string("\0\x07\0\0", 4) + std::string(8, '\0'), "m"); },
                   {"m: CDR encapsulation 0x00 0x07, expected 0x00 0x01"});
  ExpectInputError([&] { s.Decode(Cdr().Uint(1, 4).bytes(), "m"); }, {"m: field x", "needs 8 bytes", "holds 4 more"});
  ExpectInputError([&] { s.Decode(Cdr().F64(1).Str("long").Uint(0, 4).bytes(), "m"); },
                   {"m: field name", "bounds it to 3"});
  ExpectInputError([&] { s.Decode(Cdr().F64(1).Str("ok").Uint(3, 4).Uint(1, 4).Uint(1, 4).Uint(1, 4).bytes(), "m"); },
                   {"m: field v", "3 elements, its type bounds it to 2"});
  ExpectInputError([&] { s.Decode(Cdr().F64(1).Uint(1000000, 4).bytes(), "m"); }, {"m: field name", "a string of 1000000 bytes"});
  const Ros2MsgSchema seq("p/T", "float64[] v\n", "s");
  ExpectInputError([&] { seq.Decode(Cdr().Uint(4000000000u, 4).bytes(), "m"); }, {"m: field v", "4000000000 elements"});
}

TEST(Ros2Msg, JsonMessagesAndFieldPaths) {
  const MsgValue m = DecodeJsonMessage(
      R"({"header":{"stamp":{"sec":3,"nanosec":4}},"name":["hip","knee"],"position":[0.5,-1],"ok":true})", "j");
  EXPECT_EQ(At(m, "position[knee]").Number(), -1.0);
  EXPECT_EQ(At(m, "position[0]").Number(), 0.5);
  EXPECT_EQ(At(m, "header.stamp.nanosec").Number(), 4.0);
  EXPECT_EQ(At(m, "ok").Number(), 1.0);
  ExpectInputError([] { DecodeJsonMessage("[1]", "j"); }, {"j: expected a JSON object, got array"});
  ExpectInputError([] { DecodeJsonMessage("{", "j"); }, {"j: not JSON"});
  ExpectInputError([&] { ResolveField(m, ParseFieldPath("position[ankle]", "c"), "j"); },
                   {"j: name 'ankle' is not in name [hip, knee]"});
  ExpectInputError([&] { ResolveField(m, ParseFieldPath("header.stmp", "c"), "j"); },
                   {"j: no field 'stmp' in header (its fields: stamp)"});
  ExpectInputError([&] { ResolveField(m, ParseFieldPath("ok[0]", "c"), "j"); }, {"j: ok is not an array"});
  ExpectInputError([] { ParseFieldPath("a..b", "c"); }, {"c: field path 'a..b'", "empty field name"});
  ExpectInputError([] { ParseFieldPath("a[", "c"); }, {"c: field path 'a['", "expected [N] or [NAME]"});
  ExpectInputError([] { ParseFieldPath("a[1]b", "c"); }, {"expected '.' after ']'"});
  ExpectInputError([] { ParseFieldPath("a.", "c"); }, {"ends with '.'"});
}

}  // namespace
}  // namespace exotwin
