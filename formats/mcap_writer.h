// A streaming MCAP writer (mcap.dev/spec, version 0; the constants in formats/mcap_format.h): header,
// schemas and channels in the data section as they are added, messages in chunks (uncompressed or
// zstd) each followed by its message indexes, metadata records, then on Close the data-end record
// (CRC of the data section), the summary section (schemas, channels, statistics, metadata indexes,
// chunk indexes; summary offsets for each group) and the footer (CRC of the summary). Every chunk
// carries the CRC of its uncompressed records.
//
// Streaming: a chunk is written (and flushed to the file) once its records reach Options::chunk_size,
// so a run's messages reach the disk as it goes; a thread of the writer's own compresses, checksums
// and writes each full chunk while the caller fills the next (the caller waits only when it fills one
// before the last is written). The destructor closes the file properly (the last chunk, the summary
// and the footer) when Close was not called, e.g. while an exception unwinds, so what was recorded
// stays readable through the indexes as well as by streaming.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "formats/mcap_format.h"

namespace exotwin::mcap {

enum class Compression { kNone, kZstd };

class McapWriter {
 public:
  struct Options {
    std::string profile = kProfileRos2;  // Header.profile (mcap.dev/spec/registry)
    std::string library = "exotwin";     // Header.library
    Compression compression = Compression::kZstd;
    size_t chunk_size = 1 << 20;  // bytes of uncompressed records after which a chunk is written
    int zstd_level = -3;          // zstd --fast=3: the writer keeps pace with the run; files ~7 % above level 1
  };

  // Creates (truncates) `path`, its missing parent folders first, and writes the magic and the header.
  // Throws InputError naming the file if it cannot be written.
  McapWriter(const std::string& path, const Options& options);
  // Closes the file as Close() does; an error is then reported on stderr, not thrown.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // A schema record (ids from 1); `data` the schema text (for ros2msg: the message definition).
  uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  // A channel record (ids from 0) on schema `schema_id` (0: no schema).
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                      const std::map<std::string, std::string>& metadata = {});
  // A message record on `channel_id` (sequence: the channel's count of messages so far); times in ns.
  void Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, const uint8_t* data, size_t size);
  // A metadata record (written at once, outside the chunks) and its index in the summary.
  void AddMetadata(const std::string& name, const std::map<std::string, std::string>& metadata);
  // Writes the last chunk, the data end, the summary and the footer, and closes the file. Throws
  // InputError naming the file on a write error. Later calls do nothing.
  void Close();

  const std::string& path() const { return path_; }
  uint64_t message_count() const { return message_count_; }

 private:
  struct ChunkIndex {
    uint64_t start_time, end_time, offset, length, message_index_length, compressed_size, uncompressed_size;
    std::map<uint16_t, uint64_t> message_index_offsets;
  };
  struct MetadataIndex {
    uint64_t offset, length;
    std::string name;
  };
  // A chunk's content: its records, time range and each channel's (log_time, offset) pairs (indexed by
  // channel id; empty: no message of that channel).
  struct Chunk {
    std::string records;
    uint64_t start = 0, end = 0;
    std::vector<std::vector<std::pair<uint64_t, uint64_t>>> index;
    bool empty() const { return records.empty(); }
  };
  struct Worker;  // the thread that writes full chunks (mcap_writer.cc)

  void WriteData(std::string_view bytes);    // appended to the data section (its CRC and offset)
  void WriteChunk(Chunk& chunk);             // compresses and writes it with its message indexes
  void HandOver();                           // the chunk being filled to the worker
  void Drain();                              // returns once the worker wrote what it holds
  void StopWorker();                         // ends the worker's thread
  void WriteSummary();                       // the data end, the summary and the footer; closes the file

  std::string path_;
  Options options_;
  std::FILE* file_ = nullptr;
  bool closed_ = false;
  // Written by the worker while it holds a chunk, by the caller otherwise (after Drain).
  uint64_t offset_ = 0;     // bytes written so far
  uint32_t data_crc_ = 0;   // CRC-32 of the data section so far
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<char> compressed_;  // the chunk's compression buffer, reused
  void* zstd_ = nullptr;          // the worker's ZSTD_CCtx
  // The caller's.
  std::vector<std::string> schema_records_, channel_records_;  // as written, for the summary
  std::vector<uint32_t> channel_sequence_;
  std::map<uint16_t, uint64_t> channel_message_counts_;
  std::vector<MetadataIndex> metadata_indexes_;
  uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  Chunk chunk_;  // the chunk being filled
  std::unique_ptr<Worker> worker_;
};

}  // namespace exotwin::mcap
