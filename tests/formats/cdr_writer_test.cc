// The CDR encoder against byte strings computed by hand from the OMG CDR rules (little-endian, the
// encapsulation header 00 01 00 00, each primitive aligned to its size from the end of the header), and
// the MCAP writer's file closed by its destructor while an exception unwinds (the bags' round trip
// through Foxglove's reader is tests/cli/mcap_write_test.sh).
#include "formats/cdr_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/mcap_format.h"
#include "formats/mcap_writer.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

TEST(CdrWriter, JointStateBytes) {
  cdr::CdrWriter w;
  const double position[] = {1.0}, effort[] = {-2.0};
  cdr::JointState(w, 1500000000, "", {"hip"}, position, nullptr, effort, 1);
  const std::vector<uint8_t> expected = {
      0x00, 0x01, 0x00, 0x00,                          // encapsulation: CDR_LE
      0x01, 0x00, 0x00, 0x00,                          // 0: header.stamp.sec 1
      0x00, 0x65, 0xCD, 0x1D,                          // 4: nanosec 500000000 = 0x1DCD6500
      0x01, 0x00, 0x00, 0x00, 0x00,                    // 8: frame_id "" (length 1 with its NUL)
      0x00, 0x00, 0x00,                                // 13: padding to 16
      0x01, 0x00, 0x00, 0x00,                          // 16: name: 1 string
      0x04, 0x00, 0x00, 0x00, 'h', 'i', 'p', 0x00,     // 20: "hip"
      0x01, 0x00, 0x00, 0x00,                          // 28: position: 1 value
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  // 32 (aligned to 8): 1.0
      0x00, 0x00, 0x00, 0x00,                          // 40: velocity: empty
      0x01, 0x00, 0x00, 0x00,                          // 44: effort: 1 value
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // 48: -2.0
  };
  EXPECT_EQ(w.bytes(), expected);
}

TEST(CdrWriter, Float64MultiArrayBytes) {
  cdr::CdrWriter w;
  const double data[] = {0.5, -1.0};
  cdr::Float64MultiArray(w, "a,b", data, 2);
  const std::vector<uint8_t> expected = {
      0x00, 0x01, 0x00, 0x00,                          // encapsulation
      0x01, 0x00, 0x00, 0x00,                          // 0: layout.dim: 1 dimension
      0x04, 0x00, 0x00, 0x00, 'a', ',', 'b', 0x00,     // 4: label "a,b"
      0x02, 0x00, 0x00, 0x00,                          // 12: size 2
      0x02, 0x00, 0x00, 0x00,                          // 16: stride 2
      0x00, 0x00, 0x00, 0x00,                          // 20: data_offset 0
      0x02, 0x00, 0x00, 0x00,                          // 24: data: 2 values
      0x00, 0x00, 0x00, 0x00,                          // 28: padding to 32
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F,  // 32: 0.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0xBF,  // 40: -1.0
  };
  EXPECT_EQ(w.bytes(), expected);
  w.Reset();  // a new message: the header alone
  EXPECT_EQ(w.bytes(), std::vector<uint8_t>({0x00, 0x01, 0x00, 0x00}));
}

TEST(CdrWriter, TimeBeforeTheEpochKeepsNanosecondsPositive) {
  cdr::CdrWriter w;
  cdr::Time(w, -1);  // builtin_interfaces/Time: sec -1, nanosec 999999999
  EXPECT_EQ(w.bytes(), std::vector<uint8_t>({0x00, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xC9, 0x9A, 0x3B}));
}

TEST(CdrWriter, DefinitionsCarryTheirDependencies) {
  const std::string& js = cdr::JointStateDefinition();
  EXPECT_NE(js.find("std_msgs/Header header\n"), std::string::npos);
  EXPECT_NE(js.find("\n" + std::string(80, '=') + "\nMSG: std_msgs/Header\n"), std::string::npos);
  EXPECT_NE(js.find("\n" + std::string(80, '=') + "\nMSG: builtin_interfaces/Time\n"), std::string::npos);
  const std::string& fa = cdr::Float64MultiArrayDefinition();
  EXPECT_NE(fa.find("MSG: std_msgs/MultiArrayLayout\n"), std::string::npos);
  EXPECT_NE(fa.find("MSG: std_msgs/MultiArrayDimension\n"), std::string::npos);
}

uint64_t Le64(const std::string& b, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

// A writer destroyed while an exception unwinds closes the file: the last chunk, the data end, the
// summary (starting with the schema) and the footer with the magic after it.
TEST(McapWriter, DestructorClosesTheFileWhileAnExceptionUnwinds) {
  const testing::ScopedTempDir tmp("mcap");
  const std::string path = tmp.path() + "/cut.mcap";
  try {
    mcap::McapWriter w(path, {});
    const uint16_t s = w.AddSchema(cdr::kFloat64MultiArrayType, mcap::kSchemaEncodingRos2Msg,
                                   cdr::Float64MultiArrayDefinition());
    const uint16_t c = w.AddChannel(s, "/x", mcap::kMessageEncodingCdr);
    cdr::CdrWriter m;
    const double v = 1.0;
    cdr::Float64MultiArray(m, "x", &v, 1);
    for (uint64_t t = 0; t < 10; ++t) w.Write(c, t, t, m.bytes().data(), m.bytes().size());
    throw std::runtime_error("a fault mid-run");
  } catch (const std::runtime_error&) {
  }
  std::ifstream f(path, std::ios::binary);
  const std::string b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_GT(b.size(), 16u + 29u);
  EXPECT_EQ(std::memcmp(b.data(), mcap::kMagic, 8), 0);
  EXPECT_EQ(std::memcmp(b.data() + b.size() - 8, mcap::kMagic, 8), 0);
  const size_t footer = b.size() - 8 - (1 + 8 + 20);
  ASSERT_EQ(static_cast<uint8_t>(b[footer]), mcap::kFooter);
  const uint64_t summary_start = Le64(b, footer + 9), summary_offsets = Le64(b, footer + 17);
  ASSERT_LT(summary_start, summary_offsets);
  ASSERT_LT(summary_offsets, footer);
  EXPECT_EQ(static_cast<uint8_t>(b[summary_start - 13]), mcap::kDataEnd);
  EXPECT_EQ(static_cast<uint8_t>(b[summary_start]), mcap::kSchema);
  EXPECT_EQ(static_cast<uint8_t>(b[summary_offsets]), mcap::kSummaryOffset);
  std::vector<int> data_section;  // the records' opcodes from the header to the data end
  for (size_t at = 8; at < summary_start; at += 9 + Le64(b, at + 1)) data_section.push_back(static_cast<uint8_t>(b[at]));
  EXPECT_EQ(data_section, std::vector<int>({mcap::kHeader, mcap::kSchema, mcap::kChannel, mcap::kChunk,
                                            mcap::kMessageIndex, mcap::kDataEnd}));
}

}  // namespace
}  // namespace exotwin
