#include "formats/mcap_reader.h"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include <yaml-cpp/yaml.h>

#include "core/error.h"
#include "core/file_text.h"
#include "core/yaml_fields.h"
#include "formats/mcap_format.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

using mcap::Crc32;
using mcap::kFooterLength;
using mcap::kRecordPrefix;
constexpr size_t kDataEndRecord = kRecordPrefix + 4;  // a Data End record: prefix and data_section_crc

std::string Hex(uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08X", v);
  return b;
}

const char* OpcodeName(uint8_t op) {
  switch (op) {
    case mcap::kHeader: return "Header";
    case mcap::kFooter: return "Footer";
    case mcap::kSchema: return "Schema";
    case mcap::kChannel: return "Channel";
    case mcap::kMessage: return "Message";
    case mcap::kChunk: return "Chunk";
    case mcap::kMessageIndex: return "Message Index";
    case mcap::kChunkIndex: return "Chunk Index";
    case mcap::kAttachment: return "Attachment";
    case mcap::kAttachmentIndex: return "Attachment Index";
    case mcap::kStatistics: return "Statistics";
    case mcap::kMetadata: return "Metadata";
    case mcap::kMetadataIndex: return "Metadata Index";
    case mcap::kSummaryOffset: return "Summary Offset";
    case mcap::kDataEnd: return "Data End";
    default: return "unknown";
  }
}

// The fields of one record's content, read in order, little-endian. `where` names the record
// ("FILE: byte N: Chunk record") in the message of a field running past the record's end.
class Fields {
 public:
  Fields(const char* p, size_t n, std::string where) : p_(p), end_(p + n), where_(std::move(where)) {}
  uint8_t U8(const char* f) { return static_cast<uint8_t>(Uint(1, f)); }
  uint16_t U16(const char* f) { return static_cast<uint16_t>(Uint(2, f)); }
  uint32_t U32(const char* f) { return static_cast<uint32_t>(Uint(4, f)); }
  uint64_t U64(const char* f) { return Uint(8, f); }
  // uint32 length-prefixed bytes (a string, a map or an array of the spec).
  std::string Bytes32(const char* f) { return Take(U32(f), f); }
  // uint64 length-prefixed bytes (a chunk's records).
  std::string Bytes64(const char* f) { return Take(U64(f), f); }
  std::string Rest() { return Take(static_cast<uint64_t>(end_ - p_), "data"); }
  const std::string& where() const { return where_; }

 private:
  uint64_t Uint(int size, const char* f) {
    Need(static_cast<uint64_t>(size), f);
    uint64_t v = 0;
    for (int i = size; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(p_[i]);
    p_ += size;
    return v;
  }
  std::string Take(uint64_t n, const char* f) {
    Need(n, f);
    std::string s(p_, static_cast<size_t>(n));
    p_ += n;
    return s;
  }
  void Need(uint64_t n, const char* f) const {
    if (n > static_cast<uint64_t>(end_ - p_))
      throw InputError(where_ + ": field " + f + " needs " + std::to_string(n) + " bytes, the record holds " +
                       std::to_string(end_ - p_) + " more (a corrupt record)");
  }
  const char* p_;
  const char* end_;
  std::string where_;
};

// The records of one file, gathered into a McapRecord.
class FileReader {
 public:
  FileReader(const std::string& bytes, const std::string& source, const TopicFilter& wanted, McapRecord* out)
      : b_(bytes), src_(source), wanted_(wanted), out_(out) {}

  // Returns true when the file was read through its summary's chunk indexes.
  bool Read() {
    const size_t n = b_.size();
    if (n < sizeof mcap::kMagic || std::memcmp(b_.data(), mcap::kMagic, sizeof mcap::kMagic) != 0)
      throw InputError(src_ + ": byte 0: not an MCAP file (expected the magic 0x89 \"MCAP0\\r\\n\")");
    // The footer (fixed size) and the closing magic; a file without them is read linearly until it
    // ends, to name where it was cut.
    const size_t footer_at = n >= 2 * sizeof mcap::kMagic + kRecordPrefix + kFooterLength
                                 ? n - sizeof mcap::kMagic - kRecordPrefix - kFooterLength
                                 : 0;
    const bool closed = footer_at > 0 &&
                        std::memcmp(b_.data() + n - sizeof mcap::kMagic, mcap::kMagic, sizeof mcap::kMagic) == 0 &&
                        static_cast<uint8_t>(b_[footer_at]) == mcap::kFooter && Le(footer_at + 1, 8) == kFooterLength;
    if (closed) {
      const uint64_t summary_start = Le(footer_at + kRecordPrefix, 8);
      if (summary_start != 0) {
        if (summary_start < sizeof mcap::kMagic || summary_start > footer_at)
          throw InputError(At(footer_at) + "Footer record: summary_start " + std::to_string(summary_start) +
                           " is outside the file's records (bytes 8 .. " + std::to_string(footer_at) + ")");
        CheckSummaryCrc(footer_at, summary_start);
        ReadRecords(summary_start, footer_at, Section::kSummary);
        if (!chunk_indexes_.empty() && ReadIndexed(summary_start)) {
          CheckStatistics();
          return true;
        }
        // No chunk index, or messages outside the chunks: the data section is read record by
        // record; its Schema and Channel records repeat the summary's.
      }
    }
    ReadRecords(sizeof mcap::kMagic, n, Section::kData);
    if (!footer_seen_)
      throw InputError(At(n) + "the file ends before its Footer record (truncated; expected Data End, the "
                               "summary, Footer and the closing magic)");
    CheckStatistics();
    return false;
  }

 private:
  // kDefinitions: the data section's own Schema and Channel records only (chunks and messages
  // skipped), before its chunks are read through the indexes.
  enum class Section { kData, kSummary, kChunk, kDefinitions };

  std::string At(size_t offset) const { return src_ + ": byte " + std::to_string(offset) + ": "; }

  uint64_t Le(size_t at, int size) const {
    uint64_t v = 0;
    for (int i = size; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(b_[at + i]);
    return v;
  }

  // The footer's summary CRC: bytes from summary_start through the footer's summary_offset_start.
  void CheckSummaryCrc(size_t footer_at, size_t summary_start) const {
    const uint32_t stored = static_cast<uint32_t>(Le(footer_at + kRecordPrefix + 16, 4));
    if (stored == 0) return;
    const size_t end = footer_at + kRecordPrefix + 16;
    const uint32_t computed = Crc32(b_.data() + summary_start, end - summary_start);
    if (computed != stored)
      throw InputError(At(footer_at) + "Footer record: summary CRC " + Hex(stored) + " but the summary (bytes " +
                       std::to_string(summary_start) + " .. " + std::to_string(end) + ") has CRC " + Hex(computed) +
                       " (a corrupt file)");
  }

  // The records of [begin, end) of `data` (the file, or a chunk's decompressed records whose own
  // offset in the file is `chunk_at`).
  void ReadRecords(size_t begin, size_t end, Section section, const std::string* data = nullptr,
                   size_t chunk_at = 0) {
    const std::string& d = data ? *data : b_;
    for (size_t at = begin; at < end;) {
      const std::string where = section == Section::kChunk ? src_ + ": chunk at byte " + std::to_string(chunk_at) +
                                                                 ", byte " + std::to_string(at) + " of its records"
                                                           : src_ + ": byte " + std::to_string(at);
      if (end - at < kRecordPrefix)
        throw InputError(where + ": " + std::to_string(end - at) + " bytes left, expected a record (opcode and " +
                         "length; truncated)");
      const uint8_t op = static_cast<uint8_t>(d[at]);
      uint64_t len = 0;
      for (int i = 8; i-- > 0;) len = (len << 8) | static_cast<unsigned char>(d[at + 1 + i]);
      const std::string rec = where + ": " + OpcodeName(op) + " record (opcode " + std::to_string(op) + ")";
      if (len > end - at - kRecordPrefix)
        throw InputError(rec + " of " + std::to_string(len) + " bytes runs past the end " +
                         (section == Section::kChunk ? "of the chunk" : "of the file") + " at byte " +
                         std::to_string(end) + " (truncated)");
      Fields f(d.data() + at + kRecordPrefix, static_cast<size_t>(len), rec);
      const size_t next = at + kRecordPrefix + static_cast<size_t>(len);
      switch (op) {
        case mcap::kHeader:
          if ((section != Section::kData && section != Section::kDefinitions) || at != sizeof mcap::kMagic)
            throw InputError(rec + ": a Header record only opens the file (byte 8)");
          break;
        case mcap::kSchema: Schema(f); break;
        case mcap::kChannel: Channel(f); break;
        case mcap::kMessage:
          if (section == Section::kSummary) throw InputError(rec + ": a Message record in the summary section");
          if (section == Section::kDefinitions) loose_messages_ = true;
          else Message(f, where);
          break;
        case mcap::kChunk:
          if (section == Section::kData) Chunk(f, at);
          else if (section != Section::kDefinitions) throw InputError(rec + ": a Chunk record outside the data section");
          break;
        case mcap::kDataEnd:
          if (section != Section::kData)
            throw InputError(rec + ": a Data End record " +
                             (section == Section::kDefinitions ? "before the end of the data section" : "outside it"));
          DataEnd(f, at);
          section = Section::kSummary;
          break;
        case mcap::kChunkIndex:
          if (section == Section::kSummary) chunk_indexes_.push_back(ChunkIndex(f));
          break;
        case mcap::kStatistics:
          if (section == Section::kSummary) Statistics(f);
          break;
        case mcap::kFooter:
          if (section == Section::kChunk) throw InputError(rec + ": a Footer record inside a chunk");
          Footer(next, end);
          return;
        default:  // indexes, attachments, metadata, opcodes of later versions: skipped (mcap.dev/spec)
          break;
      }
      at = next;
    }
  }

  void Schema(Fields& f) {
    McapSchema s;
    s.id = f.U16("id");
    s.name = f.Bytes32("name");
    s.encoding = f.Bytes32("encoding");
    s.data = f.Bytes32("data");
    if (s.id == 0) throw InputError(f.where() + ": schema id 0 is reserved (a channel without a schema)");
    schemas_.emplace(s.id, std::move(s));  // a repeated schema (chunks, summary) keeps the first
  }

  void Channel(Fields& f) {
    const uint16_t id = f.U16("id");
    const uint16_t schema_id = f.U16("schema_id");
    McapChannel c;
    c.topic = f.Bytes32("topic");
    c.message_encoding = f.Bytes32("message_encoding");
    f.Bytes32("metadata");
    if (channels_.count(id)) return;  // repeated (chunks, summary)
    if (schema_id != 0) {
      const auto s = schemas_.find(schema_id);
      if (s == schemas_.end())
        throw InputError(f.where() + ": channel " + std::to_string(id) + " (" + ShownText(c.topic) + ") names schema " +
                         std::to_string(schema_id) + ", which no Schema record before it defines");
      c.schema = s->second;
    }
    for (size_t i = 0; i < out_->channels.size(); ++i) {
      const McapChannel& o = out_->channels[i];
      if (o.topic != c.topic) continue;
      if (o.message_encoding != c.message_encoding || o.schema.name != c.schema.name ||
          o.schema.encoding != c.schema.encoding || o.schema.data != c.schema.data)
        throw InputError(f.where() + ": topic " + ShownText(c.topic) + " again with another message type (" +
                         ShownText(c.schema.name) + ", " + ShownText(c.message_encoding) + "; before: " +
                         ShownText(o.schema.name) + ", " + ShownText(o.message_encoding) +
                         "), expected one type per topic");
      channels_[id] = i;
      return;
    }
    channels_[id] = out_->channels.size();
    out_->channels.push_back(std::move(c));
  }

  void Message(Fields& f, const std::string& where) {
    McapMessage m;
    const uint16_t id = f.U16("channel_id");
    m.sequence = f.U32("sequence");
    m.log_time = f.U64("log_time");
    m.publish_time = f.U64("publish_time");
    m.data = f.Rest();
    const auto c = channels_.find(id);
    if (c == channels_.end())
      throw InputError(f.where() + ": message of channel " + std::to_string(id) +
                       ", which no Channel record before it defines");
    ++seen_[id];
    if (!Wanted(c->second)) return;
    m.channel = c->second;
    m.where = where;
    out_->messages.push_back(std::move(m));
  }

  void Chunk(Fields& f, size_t at) {
    f.U64("message_start_time");
    f.U64("message_end_time");
    const uint64_t size = f.U64("uncompressed_size");
    const uint32_t crc = f.U32("uncompressed_crc");
    const std::string compression = f.Bytes32("compression");
    const std::string records = f.Bytes64("records");
    const std::string data = Decompress(compression, records, size, f.where());
    if (crc != 0) {
      const uint32_t computed = Crc32(data.data(), data.size());
      if (computed != crc)
        throw InputError(f.where() + ": uncompressed CRC " + Hex(crc) + " but the records have CRC " + Hex(computed) +
                         " (a corrupt chunk)");
    }
    ++out_->chunks_read;
    ReadRecords(0, data.size(), Section::kChunk, &data, at);
  }

  // A chunk's records as stored: "" (none), zstd (one or more frames) or lz4 (LZ4 frame format),
  // mcap.dev/spec/registry. The output grows as it is produced, never beyond `size`.
  static std::string Decompress(const std::string& compression, const std::string& in, uint64_t size,
                                const std::string& where) {
    const auto wrong_size = [&](uint64_t got) {
      return InputError(where + ": the " + (compression.empty() ? std::string("uncompressed") : compression) +
                        " records hold " + (got > size ? "more than " + std::to_string(size) : std::to_string(got)) +
                        " bytes, the chunk's uncompressed_size says " + std::to_string(size) + " (a corrupt chunk)");
    };
    if (compression.empty()) {
      if (in.size() != size) throw wrong_size(in.size());
      return in;
    }
    std::string out;
    const auto grow = [&](size_t used) {
      if (used == size) return false;
      out.resize(static_cast<size_t>(std::min<uint64_t>(size, std::max<uint64_t>(2 * out.size(), 1 << 16))));
      return true;
    };
    size_t used = 0;
    if (compression == mcap::kCompressionZstd) {
      std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> z(ZSTD_createDCtx(), ZSTD_freeDCtx);
      ZSTD_inBuffer src{in.data(), in.size(), 0};
      size_t last = 1;  // ZSTD_decompressStream's hint: 0 when a frame is complete
      while (src.pos < src.size || last != 0) {
        if (used == out.size() && !grow(used)) {
          if (src.pos < src.size || last != 0) throw wrong_size(size + 1);
          break;
        }
        ZSTD_outBuffer dst{out.data(), out.size(), used};
        const size_t before_in = src.pos;
        last = ZSTD_decompressStream(z.get(), &dst, &src);
        if (ZSTD_isError(last))
          throw InputError(where + ": zstd: " + ZSTD_getErrorName(last) + " (a corrupt chunk)");
        if (dst.pos == used && src.pos == before_in && used < out.size())
          throw InputError(where + ": zstd: the records end inside a frame (a truncated chunk)");
        used = dst.pos;
      }
    } else if (compression == mcap::kCompressionLz4) {
      LZ4F_dctx* raw = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) throw std::bad_alloc();
      std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> z(raw, LZ4F_freeDecompressionContext);
      size_t pos = 0, hint = 1;
      while (pos < in.size() || hint != 0) {
        if (used == out.size() && !grow(used)) {
          if (pos < in.size() || hint != 0) throw wrong_size(size + 1);
          break;
        }
        size_t dst = out.size() - used, src = in.size() - pos;
        hint = LZ4F_decompress(z.get(), out.data() + used, &dst, in.data() + pos, &src, nullptr);
        if (LZ4F_isError(hint))
          throw InputError(where + ": lz4: " + LZ4F_getErrorName(hint) + " (a corrupt chunk)");
        if (dst == 0 && src == 0 && used < out.size())
          throw InputError(where + ": lz4: the records end inside a frame (a truncated chunk)");
        pos += src, used += dst;
      }
    } else {
      throw InputError(where + ": unknown compression '" + ShownText(compression) + "', expected none (''), zstd or lz4");
    }
    if (used != size) throw wrong_size(used);
    out.resize(used);
    return out;
  }

  // Data End: the CRC of every byte before this record (mcap.dev/spec#data-end-op0x0f).
  void DataEnd(Fields& f, size_t at) {
    const uint32_t stored = f.U32("data_section_crc");
    if (stored == 0) return;
    const uint32_t computed = Crc32(b_.data(), at);
    if (computed != stored)
      throw InputError(f.where() + ": data section CRC " + Hex(stored) + " but bytes 0 .. " + std::to_string(at) +
                       " have CRC " + Hex(computed) + " (a corrupt file)");
  }

  void Footer(size_t next, size_t end) {
    footer_seen_ = true;
    if (end - next != sizeof mcap::kMagic || std::memcmp(b_.data() + next, mcap::kMagic, sizeof mcap::kMagic) != 0)
      throw InputError(At(next) + "expected the closing magic after the Footer record and the end of the file (" +
                       std::to_string(end - next) + " bytes follow; truncated or corrupt)");
  }

  struct Index {
    uint64_t start_time, offset, length;
    std::vector<uint16_t> channels;  // the channels its message index names (empty: none given)
    std::string where;
  };
  Index ChunkIndex(Fields& f) {
    Index i;
    i.start_time = f.U64("message_start_time");
    f.U64("message_end_time");
    i.offset = f.U64("chunk_start_offset");
    i.length = f.U64("chunk_length");
    const std::string offsets = f.Bytes32("message_index_offsets");  // uint16 channel id -> uint64 offset
    for (size_t k = 0; k + 10 <= offsets.size(); k += 10)
      i.channels.push_back(static_cast<uint16_t>(static_cast<unsigned char>(offsets[k]) |
                                                 static_cast<unsigned char>(offsets[k + 1]) << 8));
    i.where = f.where();
    return i;
  }

  // The data section through the summary: its own Schema and Channel records, then the chunks the
  // Chunk Index records point at, in message_start_time order (a stable sort: file order among
  // equal times). False, having read no message, when the data section holds messages outside its
  // chunks (the indexes do not cover them).
  bool ReadIndexed(size_t summary_start) {
    if (summary_start < sizeof mcap::kMagic + kDataEndRecord ||
        static_cast<uint8_t>(b_[summary_start - kDataEndRecord]) != mcap::kDataEnd ||
        Le(summary_start - kDataEndRecord + 1, 8) != 4)
      throw InputError(At(summary_start) + "expected a Data End record just before the summary section");
    {
      Fields f(b_.data() + summary_start - 4, 4, At(summary_start - kDataEndRecord) + "Data End record");
      DataEnd(f, summary_start - kDataEndRecord);
    }
    ReadRecords(sizeof mcap::kMagic, summary_start - kDataEndRecord, Section::kDefinitions);
    if (loose_messages_) return false;
    std::stable_sort(chunk_indexes_.begin(), chunk_indexes_.end(),
                     [](const Index& a, const Index& b) { return a.start_time < b.start_time; });
    const size_t data_end = summary_start - kDataEndRecord;
    for (const Index& i : chunk_indexes_) {
      if (i.offset < sizeof mcap::kMagic || i.offset >= data_end || i.length > data_end - i.offset ||
          i.length < kRecordPrefix || static_cast<uint8_t>(b_[i.offset]) != mcap::kChunk ||
          Le(i.offset + 1, 8) != i.length - kRecordPrefix)
        throw InputError(i.where + ": chunk_start_offset " + std::to_string(i.offset) + ", chunk_length " +
                         std::to_string(i.length) + " do not hold a Chunk record of the data section");
      // A chunk holding only other topics' messages (its channels all defined) is not read.
      if (wanted_ && !i.channels.empty() &&
          std::all_of(i.channels.begin(), i.channels.end(), [&](uint16_t id) {
            const auto c = channels_.find(id);
            return c != channels_.end() && !Wanted(c->second);
          })) {
        skipped_chunks_ = true;
        ++out_->chunks_skipped;
        continue;
      }
      ReadRecords(i.offset, i.offset + i.length, Section::kData);
    }
    return true;
  }

  bool Wanted(size_t channel) const { return !wanted_ || wanted_(out_->channels[channel].topic); }

  void Statistics(Fields& f) {
    has_statistics_ = true;
    statistics_count_ = f.U64("message_count");
    f.U16("schema_count");
    for (const char* n : {"channel_count", "attachment_count", "metadata_count", "chunk_count"}) f.U32(n);
    f.U64("message_start_time");
    f.U64("message_end_time");
    const std::string counts = f.Bytes32("channel_message_counts");  // uint16 channel id -> uint64 count
    for (size_t k = 0; k + 10 <= counts.size(); k += 10) {
      uint64_t n = 0;
      for (int b = 10; b-- > 2;) n = (n << 8) | static_cast<unsigned char>(counts[k + b]);
      channel_counts_[static_cast<uint16_t>(static_cast<unsigned char>(counts[k]) |
                                            static_cast<unsigned char>(counts[k + 1]) << 8)] = n;
    }
  }

  // The Statistics' message_count against the messages read; with chunks left unread, each wanted
  // channel's count in channel_message_counts.
  void CheckStatistics() const {
    if (!has_statistics_) return;
    uint64_t seen = 0;
    for (const auto& [id, n] : seen_) seen += n;
    if (!skipped_chunks_ && statistics_count_ != seen)
      throw InputError(src_ + ": Statistics record: message_count " + std::to_string(statistics_count_) +
                       " but the file holds " + std::to_string(seen) + " messages (a corrupt or truncated file)");
    if (!skipped_chunks_) return;
    for (const auto& [id, n] : channel_counts_) {
      const auto c = channels_.find(id);
      if (c == channels_.end() || !Wanted(c->second)) continue;
      const auto s = seen_.find(id);
      const uint64_t got = s == seen_.end() ? 0 : s->second;
      if (got != n)
        throw InputError(src_ + ": Statistics record: channel " + std::to_string(id) + " (" +
                         ShownText(out_->channels[c->second].topic) + ") has " + std::to_string(n) +
                         " messages, the chunks hold " + std::to_string(got) + " (a corrupt file)");
    }
  }

  const std::string& b_;
  const std::string& src_;
  const TopicFilter& wanted_;
  McapRecord* out_;
  std::map<uint16_t, McapSchema> schemas_;
  std::map<uint16_t, size_t> channels_;  // channel id -> index in out_->channels
  std::vector<Index> chunk_indexes_;
  bool footer_seen_ = false, has_statistics_ = false, loose_messages_ = false, skipped_chunks_ = false;
  uint64_t statistics_count_ = 0;
  std::map<uint16_t, uint64_t> channel_counts_;  // the Statistics' channel_message_counts
  std::map<uint16_t, uint64_t> seen_;            // messages read per channel id, kept or not
};

bool ParseInto(const std::string& bytes, const std::string& source, const TopicFilter& wanted, McapRecord* out) {
  return FileReader(bytes, source, wanted, out).Read();
}

}  // namespace

int McapRecord::Find(const std::string& topic) const {
  for (size_t i = 0; i < channels.size(); ++i)
    if (channels[i].topic == topic) return static_cast<int>(i);
  return -1;
}

bool IsBagPath(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return fs::exists(fs::path(path) / "metadata.yaml", ec);
  if (path.size() > 5 && path.compare(path.size() - 5, 5, ".mcap") == 0) return true;
  char head[sizeof mcap::kMagic] = {};
  std::ifstream in(path, std::ios::binary);
  return in.read(head, sizeof head) && std::memcmp(head, mcap::kMagic, sizeof head) == 0;
}

McapRecord ParseMcap(const std::string& bytes, const std::string& source, const TopicFilter& wanted) {
  McapRecord r;
  r.source = source;
  r.indexed = ParseInto(bytes, source, wanted, &r);
  return r;
}

McapRecord ReadMcapRecord(const std::string& path, const TopicFilter& wanted) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return ParseMcap(ReadBinaryFile(path, "MCAP"), path, wanted);
  // A rosbag2 folder (github.com/ros2/rosbag2, metadata.yaml): its files in order, one record.
  const std::string meta = (fs::path(path) / "metadata.yaml").string();
  const YAML::Node root = ParseYaml(ReadYamlText(meta, "rosbag2 metadata"), meta);
  const YamlContext c{meta};
  const YAML::Node info = root.IsMap() ? root["rosbag2_bagfile_information"] : YAML::Node();
  if (!info || !info.IsMap())
    c.Fail("rosbag2_bagfile_information", "missing, expected rosbag2's metadata (a rosbag2 folder)");
  if (const YAML::Node id = info["storage_identifier"]; id && (!id.IsScalar() || id.Scalar() != "mcap"))
    c.Fail("rosbag2_bagfile_information.storage_identifier",
           "'" + (id.IsScalar() ? id.Scalar() : std::string("?")) + "', expected mcap" + YamlLine(id));
  const YAML::Node files = info["relative_file_paths"];
  if (!files || !files.IsSequence() || files.size() == 0)
    c.Fail("rosbag2_bagfile_information.relative_file_paths", "missing or empty, expected the bag's .mcap files");
  McapRecord r;
  r.source = path;
  r.indexed = true;
  for (const YAML::Node& f : files) {
    if (!f.IsScalar() || f.Scalar().empty())
      c.Fail("rosbag2_bagfile_information.relative_file_paths", "expected file names" + YamlLine(f));
    const std::string file = (fs::path(path) / f.Scalar()).string();
    // Each file has its own channel ids; topics are merged by name into r.
    r.indexed = ParseInto(ReadBinaryFile(file, "MCAP"), file, wanted, &r) && r.indexed;
  }
  return r;
}

}  // namespace exotwin
