// Reading MCAP files (mcap.dev/spec, version 0) and rosbag2 folders of them (DESIGN.md "ROS 2 bags
// (MCAP) in and out"). The reader yields the channels and messages as stored; decoding a message's
// bytes is formats/ros2msg.h's job.
//
// What is read: the magic at both ends; every record of the data section (Header, Schema, Channel,
// Message, Chunk; the others skipped, unknown opcodes too, as the spec asks); chunks stored
// uncompressed, zstd (libzstd) or lz4 (liblz4's frame format); the summary section when the footer
// points at one: its Schema and Channel records, its Chunk Index records (the chunks are then read
// through them, in message_start_time order, after the data section's own Schema and Channel
// records), its Statistics (message count checked). A file without a summary, without chunk indexes,
// or with messages outside its chunks is read linearly. CRC-32 (zlib's crc32; 0 = not computed) checked: the Data End record's
// data-section CRC, each chunk's uncompressed CRC, the footer's summary CRC.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace exotwin {

struct McapSchema {
  uint16_t id = 0;
  std::string name;      // e.g. "sensor_msgs/msg/JointState"
  std::string encoding;  // "ros2msg", "jsonschema", ...
  std::string data;      // the schema's text (ros2msg: the message definition)
};

struct McapChannel {
  std::string topic;             // e.g. "/exo/joint_states"
  std::string message_encoding;  // "cdr", "json", ...
  McapSchema schema;             // id 0: the channel has no schema
};

struct McapMessage {
  size_t channel = 0;  // index into McapRecord::channels
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;  // ns
  std::string data;                         // the message's bytes as stored
  std::string where;                        // "FILE: byte N" (or "..., chunk at byte N"), for messages
};

// A bag: one MCAP file, or every file of a rosbag2 folder, as one record. Channels of the same topic
// (in one file or across files) are one channel when their schema and encoding agree.
struct McapRecord {
  std::string source;                 // the path given
  std::vector<McapChannel> channels;  // in order of first appearance
  std::vector<McapMessage> messages;  // per file: data-section order (chunks in index order); files in order;
                                      // only the wanted topics' (ParseMcap's `wanted`)
  bool indexed = false;               // every file read through its summary's chunk indexes
  size_t chunks_read = 0, chunks_skipped = 0;  // skipped: through the indexes, no wanted topic in it
  // The channel of `topic`, -1 if none.
  int Find(const std::string& topic) const;
};

// True for a path ReadMcapRecord takes: a file ending in ".mcap" or starting with the MCAP magic, or a
// folder holding metadata.yaml (a rosbag2 folder).
bool IsBagPath(const std::string& path);

// The topics whose messages a reader keeps (every channel is listed whatever it says); empty: all.
using TopicFilter = std::function<bool(const std::string& topic)>;

// Reads one MCAP file's bytes (`source` names it in messages), keeping the messages of the topics
// `wanted` takes. Through the chunk indexes, a chunk whose message index names only channels of
// other topics is not read; the Statistics are then checked per wanted channel
// (channel_message_counts). Throws InputError naming the source and the byte offset for: no MCAP
// magic at the start (not MCAP), a record running past the
// end (truncated), a record field running past its record, a bad CRC (which one, stored and
// computed), an unknown compression, a chunk that does not decompress to its uncompressed_size, a
// message of a channel never defined, a channel of a schema never defined, a Chunk Index that does
// not point at a chunk, a Statistics message count the file does not hold.
McapRecord ParseMcap(const std::string& bytes, const std::string& source, const TopicFilter& wanted = {});

// ParseMcap of the file at `path`, or of each file of the rosbag2 folder at `path` (metadata.yaml's
// rosbag2_bagfile_information.relative_file_paths, in order, relative to the folder; storage_identifier
// mcap). Throws InputError for an unreadable file, a metadata.yaml without those keys, a file it
// names that is missing, a topic whose schema or encoding differs between files.
McapRecord ReadMcapRecord(const std::string& path, const TopicFilter& wanted = {});

}  // namespace exotwin
