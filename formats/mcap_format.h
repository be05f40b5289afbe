// The MCAP container format (mcap.dev/spec, version 0), shared by the reader (formats/mcap_reader.h)
// and the writer (formats/mcap_writer.h): the magic bytes, the record opcodes, the record prefix and
// the footer's size, and the CRC. Every integer in a record is little-endian; a record is opcode
// (uint8), length (uint64), then that many bytes; strings are uint32 length + UTF-8 bytes; maps and
// arrays are uint32 byte length + entries. CRCs are CRC-32 (ISO-HDLC, zlib's crc32), 0 meaning "not
// computed".
#pragma once
#include <zlib.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace exotwin::mcap {

// The 8 bytes at the start and at the end of every MCAP file: 0x89 "MCAP" '0' "\r\n".
constexpr unsigned char kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Bytes before a record's content: opcode (uint8) and length (uint64).
constexpr size_t kRecordPrefix = 9;
// The Footer record's content: summary_start, summary_offset_start (uint64), summary_crc (uint32).
constexpr size_t kFooterLength = 20;

// CRC-32 (ISO-HDLC) of n bytes continuing `crc` (0 to start), as the spec's CRC fields hold it: zlib's
// crc32, which takes at most a uInt of bytes per call.
inline uint32_t Crc32(const void* data, size_t n, uint32_t crc = 0) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong c = crc;
  while (n > 0) {
    const uInt part = static_cast<uInt>(std::min<size_t>(n, size_t{1} << 30));
    c = crc32(c, p, part);
    p += part, n -= part;
  }
  return static_cast<uint32_t>(c);
}

// The profile and encodings exotwin reads and writes (mcap.dev/spec/registry).
constexpr const char* kProfileRos2 = "ros2";
constexpr const char* kSchemaEncodingRos2Msg = "ros2msg";
constexpr const char* kSchemaEncodingJsonSchema = "jsonschema";
constexpr const char* kMessageEncodingCdr = "cdr";
constexpr const char* kMessageEncodingJson = "json";
constexpr const char* kCompressionZstd = "zstd";
constexpr const char* kCompressionLz4 = "lz4";

}  // namespace exotwin::mcap
