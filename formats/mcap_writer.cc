// The streaming MCAP writer: see mcap_writer.h. Record layouts as mcap.dev/spec gives them.
#include "formats/mcap_writer.h"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/error.h"
#include "core/output_path.h"

namespace exotwin::mcap {
namespace {

// Little-endian serialization of the spec's field types into a record body.
struct Bytes {
  std::string s;
  void U8(uint8_t v) { s.push_back(static_cast<char>(v)); }
  void U16(uint16_t v) { Le(v, 2); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void Le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  void Str(const std::string& v) {  // uint32 length + bytes (also the spec's "Bytes" with uint32 prefix)
    U32(static_cast<uint32_t>(v.size()));
    s += v;
  }
  void StrMap(const std::map<std::string, std::string>& m) {  // uint32 byte length + entries
    Bytes e;
    for (const auto& [k, v] : m) e.Str(k), e.Str(v);
    Str(e.s);
  }
  void U16Map(const std::map<uint16_t, uint64_t>& m) {  // map<uint16, uint64>
    Bytes e;
    for (const auto& [k, v] : m) e.U16(k), e.U64(v);
    Str(e.s);
  }
};

// opcode, uint64 body length, body.
std::string Record(Opcode op, const std::string& body) {
  Bytes r;
  r.U8(op);
  r.U64(body.size());
  r.s += body;
  return r.s;
}

uint32_t Crc(uint32_t crc, const std::string& bytes) {
  return static_cast<uint32_t>(
      crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

}  // namespace

McapWriter::McapWriter(const std::string& path, const Options& options) : path_(path), options_(options) {
  CreateParentFolders(path);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  Bytes header;
  header.Str(options_.profile);
  header.Str(options_.library);
  WriteData(std::string(reinterpret_cast<const char*>(kMagic), sizeof(kMagic)) + Record(kHeader, header.s));
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exotwin: %s\n", e.what());
  }
}

void McapWriter::Fail(const std::string& what) {
  const std::string reason = std::strerror(errno);
  if (file_) std::fclose(file_);
  file_ = nullptr;
  closed_ = true;
  throw InputError(path_ + ": " + what + " (" + reason + ")");
}

void McapWriter::WriteData(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) Fail("write failed");
  data_crc_ = Crc(data_crc_, bytes);
  offset_ += bytes.size();
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  const uint16_t id = static_cast<uint16_t>(schema_records_.size() + 1);
  Bytes b;
  b.U16(id);
  b.Str(name);
  b.Str(encoding);
  b.Str(data);
  schema_records_.push_back(Record(kSchema, b.s));
  WriteData(schema_records_.back());
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                const std::map<std::string, std::string>& metadata) {
  const uint16_t id = static_cast<uint16_t>(channel_records_.size());
  Bytes b;
  b.U16(id);
  b.U16(schema_id);
  b.Str(topic);
  b.Str(message_encoding);
  b.StrMap(metadata);
  channel_records_.push_back(Record(kChannel, b.s));
  channel_sequence_.push_back(0);
  channel_message_counts_[id] = 0;
  WriteData(channel_records_.back());
  return id;
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, const uint8_t* data,
                       size_t size) {
  if (closed_) throw InputError(path_ + ": a message after the file was closed");
  if (channel_id >= channel_records_.size())
    throw InputError(path_ + ": a message on channel " + std::to_string(channel_id) + ", which was not added");
  if (chunk_message_index_.empty()) chunk_start_ = chunk_end_ = log_time;
  chunk_start_ = std::min(chunk_start_, log_time);
  chunk_end_ = std::max(chunk_end_, log_time);
  chunk_message_index_[channel_id].emplace_back(log_time, chunk_.size());
  Bytes b;
  b.U8(kMessage);
  b.U64(2 + 4 + 8 + 8 + size);
  b.U16(channel_id);
  b.U32(channel_sequence_[channel_id]++);
  b.U64(log_time);
  b.U64(publish_time);
  chunk_ += b.s;
  chunk_.append(reinterpret_cast<const char*>(data), size);
  if (message_count_ == 0) start_time_ = end_time_ = log_time;
  start_time_ = std::min(start_time_, log_time);
  end_time_ = std::max(end_time_, log_time);
  ++message_count_;
  ++channel_message_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_size) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_message_index_.empty()) return;
  const std::string* records = &chunk_;
  std::string compression;
  if (options_.compression == Compression::kZstd) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const size_t n = ZSTD_compress(compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size(),
                                   options_.zstd_level);
    if (ZSTD_isError(n)) throw InputError(path_ + ": zstd: " + ZSTD_getErrorName(n));
    compressed_.resize(n);
    records = &compressed_;
    compression = kCompressionZstd;
  }
  ChunkIndex ci{};
  ci.start_time = chunk_start_;
  ci.end_time = chunk_end_;
  ci.offset = offset_;
  ci.compressed_size = records->size();
  ci.uncompressed_size = chunk_.size();
  Bytes b;
  b.U64(chunk_start_);
  b.U64(chunk_end_);
  b.U64(chunk_.size());
  b.U32(Crc(0, chunk_));
  b.Str(compression);
  b.U64(records->size());
  // The records are appended to the record's head without copying them into it.
  Bytes head;
  head.U8(kChunk);
  head.U64(b.s.size() + records->size());
  WriteData(head.s + b.s);
  WriteData(*records);
  ci.length = offset_ - ci.offset;
  const uint64_t index_start = offset_;
  for (const auto& [channel, entries] : chunk_message_index_) {
    Bytes m;
    m.U16(channel);
    Bytes e;
    for (const auto& [t, off] : entries) e.U64(t), e.U64(off);
    m.Str(e.s);
    ci.message_index_offsets[channel] = offset_;
    WriteData(Record(kMessageIndex, m.s));
  }
  ci.message_index_length = offset_ - index_start;
  chunk_indexes_.push_back(std::move(ci));
  chunk_.clear();
  chunk_message_index_.clear();
  if (std::fflush(file_) != 0) Fail("write failed");
}

void McapWriter::AddMetadata(const std::string& name, const std::map<std::string, std::string>& metadata) {
  Bytes b;
  b.Str(name);
  b.StrMap(metadata);
  metadata_indexes_.push_back({offset_, 0, name});
  const std::string r = Record(kMetadata, b.s);
  metadata_indexes_.back().length = r.size();
  WriteData(r);
}

void McapWriter::Close() {
  if (closed_) return;
  FlushChunk();
  Bytes de;
  de.U32(data_crc_);
  WriteData(Record(kDataEnd, de.s));

  // The summary section: each group's records, then a summary offset per group.
  const uint64_t summary_start = offset_;
  std::string summary;
  std::vector<std::pair<Opcode, std::pair<uint64_t, uint64_t>>> groups;  // opcode, (start, length)
  auto group = [&](Opcode op, const std::vector<std::string>& records) {
    if (records.empty()) return;
    const uint64_t start = summary_start + summary.size();
    for (const std::string& r : records) summary += r;
    groups.push_back({op, {start, summary_start + summary.size() - start}});
  };
  group(kSchema, schema_records_);
  group(kChannel, channel_records_);
  {
    Bytes st;
    st.U64(message_count_);
    st.U16(static_cast<uint16_t>(schema_records_.size()));
    st.U32(static_cast<uint32_t>(channel_records_.size()));
    st.U32(0);  // attachments
    st.U32(static_cast<uint32_t>(metadata_indexes_.size()));
    st.U32(static_cast<uint32_t>(chunk_indexes_.size()));
    st.U64(start_time_);
    st.U64(end_time_);
    st.U16Map(channel_message_counts_);
    group(kStatistics, {Record(kStatistics, st.s)});
  }
  std::vector<std::string> metadata_index, chunk_index;
  for (const MetadataIndex& m : metadata_indexes_) {
    Bytes b;
    b.U64(m.offset);
    b.U64(m.length);
    b.Str(m.name);
    metadata_index.push_back(Record(kMetadataIndex, b.s));
  }
  group(kMetadataIndex, metadata_index);
  for (const ChunkIndex& c : chunk_indexes_) {
    Bytes b;
    b.U64(c.start_time);
    b.U64(c.end_time);
    b.U64(c.offset);
    b.U64(c.length);
    b.U16Map(c.message_index_offsets);
    b.U64(c.message_index_length);
    b.Str(options_.compression == Compression::kZstd ? kCompressionZstd : "");
    b.U64(c.compressed_size);
    b.U64(c.uncompressed_size);
    chunk_index.push_back(Record(kChunkIndex, b.s));
  }
  group(kChunkIndex, chunk_index);
  const uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& [op, range] : groups) {
    Bytes b;
    b.U8(op);
    b.U64(range.first);
    b.U64(range.second);
    summary += Record(kSummaryOffset, b.s);
  }
  // Footer: summary_crc covers the summary section through the footer's summary_offset_start field.
  Bytes footer;
  footer.U8(kFooter);
  footer.U64(8 + 8 + 4);
  footer.U64(summary_start);
  footer.U64(summary_offset_start);
  summary += footer.s;
  Bytes crc;
  crc.U32(Crc(0, summary));
  summary += crc.s;
  summary.append(reinterpret_cast<const char*>(kMagic), sizeof(kMagic));
  if (std::fwrite(summary.data(), 1, summary.size(), file_) != summary.size()) Fail("write failed");
  offset_ += summary.size();
  closed_ = true;
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

}  // namespace exotwin::mcap
