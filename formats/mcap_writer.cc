// The streaming MCAP writer: see mcap_writer.h. Record layouts as mcap.dev/spec gives them.
#include "formats/mcap_writer.h"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <string_view>
#include <thread>

#include "core/error.h"
#include "core/output_path.h"
#include "core/realtime.h"

namespace exotwin::mcap {
namespace {

// Little-endian serialization of the spec's field types into a record body.
struct Bytes {
  std::string s;
  void U8(uint8_t v) { s.push_back(static_cast<char>(v)); }
  void U16(uint16_t v) { Le(v, 2); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void Le(uint64_t v, int n) {  // the low n bytes of v, least significant first
    char b[8];
    for (int i = 0; i < n; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xFF);
    s.append(b, static_cast<size_t>(n));
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

uint32_t Crc(uint32_t crc, std::string_view bytes) { return Crc32(bytes.data(), bytes.size(), crc); }

}  // namespace

// The thread that writes full chunks: the caller hands it one at a time (HandOver) and waits for it
// only to hand over the next, to write records of its own (Drain) and to close.
struct McapWriter::Worker {
  std::mutex m;
  std::condition_variable cv;
  Chunk chunk;        // the thread's while busy
  bool busy = false, stop = false;
  std::string error;  // the first write error, reported in the caller's thread
  std::thread thread;
};

McapWriter::McapWriter(const std::string& path, const Options& options) : path_(path), options_(options) {
  CreateParentFolders(path);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  Bytes header;
  header.Str(options_.profile);
  header.Str(options_.library);
  try {
    WriteData(std::string(reinterpret_cast<const char*>(kMagic), sizeof(kMagic)) + Record(kHeader, header.s));
  } catch (...) {
    std::fclose(file_);
    throw;
  }
  chunk_.records.reserve(options_.chunk_size + (64 << 10));
  worker_ = std::make_unique<Worker>();
  Worker& w = *worker_;
  w.thread = std::thread([this, &w] {
    DropRealtimePriority();  // a real-time caller's (serve --rt-priority) tick never waits behind a chunk
    std::unique_lock<std::mutex> lock(w.m);
    for (;;) {
      w.cv.wait(lock, [&w] { return w.busy || w.stop; });
      if (!w.busy) return;
      lock.unlock();
      std::string error;
      try {
        WriteChunk(w.chunk);
      } catch (const std::exception& e) {
        error = e.what();
      }
      lock.lock();
      if (w.error.empty()) w.error = error;
      w.busy = false;
      w.cv.notify_all();
    }
  });
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exotwin: %s\n", e.what());
  }
}

void McapWriter::WriteData(std::string_view bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
  data_crc_ = Crc(data_crc_, bytes);
  offset_ += bytes.size();
}

void McapWriter::Drain() {
  if (!worker_) return;
  Worker& w = *worker_;
  std::unique_lock<std::mutex> lock(w.m);
  w.cv.wait(lock, [&w] { return !w.busy; });
  if (!w.error.empty()) throw InputError(w.error);
}

void McapWriter::HandOver() {
  if (chunk_.empty()) return;
  Drain();
  Worker& w = *worker_;
  {
    const std::lock_guard<std::mutex> lock(w.m);
    std::swap(w.chunk, chunk_);
    w.busy = true;
  }
  w.cv.notify_all();
  chunk_.records.clear();  // the chunk the worker wrote before: its buffers reused
  for (auto& entries : chunk_.index) entries.clear();
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  const uint16_t id = static_cast<uint16_t>(schema_records_.size() + 1);
  Bytes b;
  b.U16(id);
  b.Str(name);
  b.Str(encoding);
  b.Str(data);
  schema_records_.push_back(Record(kSchema, b.s));
  Drain();
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
  Drain();
  WriteData(channel_records_.back());
  return id;
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, const uint8_t* data,
                       size_t size) {
  if (closed_) throw InputError(path_ + ": a message after the file was closed");
  if (channel_id >= channel_records_.size())
    throw InputError(path_ + ": a message on channel " + std::to_string(channel_id) + ", which was not added");
  Chunk& c = chunk_;
  if (c.empty()) c.start = c.end = log_time;
  c.start = std::min(c.start, log_time);
  c.end = std::max(c.end, log_time);
  if (c.index.size() <= channel_id) c.index.resize(channel_id + 1u);
  c.index[channel_id].emplace_back(log_time, c.records.size());
  // Message: opcode, length, channel_id, sequence, log_time, publish_time, data.
  unsigned char head[1 + 8 + 2 + 4 + 8 + 8];
  auto le = [&head](size_t at, uint64_t v, int n) {
    for (int i = 0; i < n; ++i) head[at + i] = static_cast<unsigned char>(v >> (8 * i));
  };
  le(0, kMessage, 1);
  le(1, 2 + 4 + 8 + 8 + size, 8);
  le(9, channel_id, 2);
  le(11, channel_sequence_[channel_id]++, 4);
  le(15, log_time, 8);
  le(23, publish_time, 8);
  c.records.append(reinterpret_cast<const char*>(head), sizeof(head));
  c.records.append(reinterpret_cast<const char*>(data), size);
  if (message_count_ == 0) start_time_ = end_time_ = log_time;
  start_time_ = std::min(start_time_, log_time);
  end_time_ = std::max(end_time_, log_time);
  ++message_count_;
  ++channel_message_counts_[channel_id];
  if (c.records.size() >= options_.chunk_size) HandOver();
}

void McapWriter::WriteChunk(Chunk& chunk) {
  std::string compression;
  size_t compressed_size = chunk.records.size();
  if (options_.compression == Compression::kZstd) {
    if (!zstd_) zstd_ = ZSTD_createCCtx();  // one context for every chunk
    if (!zstd_) throw InputError(path_ + ": zstd: no memory for a compression context");
    const size_t bound = ZSTD_compressBound(chunk.records.size());
    if (compressed_.size() < bound) compressed_.resize(bound);
    const size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_), compressed_.data(), compressed_.size(),
                                       chunk.records.data(), chunk.records.size(), options_.zstd_level);
    if (ZSTD_isError(n)) throw InputError(path_ + ": zstd: " + ZSTD_getErrorName(n));
    compressed_size = n;
    compression = kCompressionZstd;
  }
  ChunkIndex ci{};
  ci.start_time = chunk.start;
  ci.end_time = chunk.end;
  ci.offset = offset_;
  const std::string_view records = compression.empty() ? std::string_view(chunk.records)
                                                       : std::string_view(compressed_.data(), compressed_size);
  ci.compressed_size = records.size();
  ci.uncompressed_size = chunk.records.size();
  Bytes b;
  b.U64(chunk.start);
  b.U64(chunk.end);
  b.U64(chunk.records.size());
  b.U32(Crc(0, chunk.records));
  b.Str(compression);
  b.U64(records.size());
  // The records are appended to the record's head without copying them into it.
  Bytes head;
  head.U8(kChunk);
  head.U64(b.s.size() + records.size());
  WriteData(head.s + b.s);
  WriteData(records);
  ci.length = offset_ - ci.offset;
  const uint64_t index_start = offset_;
  for (size_t channel = 0; channel < chunk.index.size(); ++channel) {
    if (chunk.index[channel].empty()) continue;
    Bytes m;
    m.U16(static_cast<uint16_t>(channel));
    Bytes e;
    for (const auto& [t, off] : chunk.index[channel]) e.U64(t), e.U64(off);
    m.Str(e.s);
    ci.message_index_offsets[static_cast<uint16_t>(channel)] = offset_;
    WriteData(Record(kMessageIndex, m.s));
  }
  ci.message_index_length = offset_ - index_start;
  chunk_indexes_.push_back(std::move(ci));
  if (std::fflush(file_) != 0) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

void McapWriter::AddMetadata(const std::string& name, const std::map<std::string, std::string>& metadata) {
  Bytes b;
  b.Str(name);
  b.StrMap(metadata);
  const std::string r = Record(kMetadata, b.s);
  Drain();
  metadata_indexes_.push_back({offset_, r.size(), name});
  WriteData(r);
}

void McapWriter::StopWorker() {
  if (worker_) {
    Worker& w = *worker_;
    {
      const std::lock_guard<std::mutex> lock(w.m);
      w.stop = true;
    }
    w.cv.notify_all();
    if (w.thread.joinable()) w.thread.join();
    worker_.reset();
  }
  ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_));  // the worker's, once it ended
  zstd_ = nullptr;
}

void McapWriter::Close() {
  if (closed_) return;
  closed_ = true;
  try {
    HandOver();
    Drain();
    StopWorker();
    WriteSummary();
  } catch (...) {
    StopWorker();
    if (file_) std::fclose(file_);
    file_ = nullptr;
    throw;
  }
}

void McapWriter::WriteSummary() {
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
  if (std::fwrite(summary.data(), 1, summary.size(), file_) != summary.size())
    throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
  offset_ += summary.size();
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

}  // namespace exotwin::mcap
