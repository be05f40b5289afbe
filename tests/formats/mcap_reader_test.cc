// The bag reader against an independent client: tests/mcap_client/write_bag.mjs writes ROS 2 bags
// with Foxglove's own libraries (@mcap/core, @foxglove/rosmsg2-serialization, @foxglove/cdr; zstd by
// @foxglove/wasm-zstd, lz4 by the reference lz4 command) in every compression and layout (chunk
// indexes and a summary, or none; no chunks), a rosbag2 folder, five topics (JointState, a
// Float64MultiArray at another rate, a message type exotwin has never seen, JSON, big-endian CDR), and
// writes what it wrote to expected.json: exotwin must read exactly those values, and the column map
// must turn the bag into exactly the record the client computes. Then broken bags (not MCAP,
// truncated, corrupt chunks, bad CRCs, an unknown compression) and wrong maps throw InputError naming
// the file and the byte offset or the topic, and no byte string crashes the reader.
#include "formats/mcap_reader.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_text.h"
#include "formats/bag_table.h"
#include "formats/column_map.h"
#include "formats/mcap_format.h"
#include "formats/ros2msg.h"
#include "tests/expect_input_error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ExpectInputError;

const char* const kVariants[] = {"none_indexed", "none_linear", "zstd_indexed", "zstd_linear",
                                 "lz4_indexed",  "lz4_linear",  "plain"};

// The client's bags, written once per test process; empty (with the reason in *why) when node or
// the client's node_modules are missing (the tests then skip), "FAILED: ..." when the client failed.
const std::string& ClientBags(std::string* why) {
  static const testing::ScopedTempDir tmp("mcap_client");
  static std::string reason;
  static const std::string dir = [] {
    const std::string client = std::string(EXOTWIN_SOURCE_DIR) + "/tests/mcap_client";
    if (std::system("node --version >/dev/null 2>&1") != 0) {
      reason = "node is not installed (scripts/setup.sh)";
      return std::string();
    }
    if (!fs::exists(client + "/node_modules/@mcap/core")) {
      reason = "tests/mcap_client/node_modules is missing (npm ci there; scripts/setup.sh does it)";
      return std::string();
    }
    const std::string out = tmp.File("bags");
    const std::string cmd = "cd '" + client + "' && node write_bag.mjs variants '" + out + "' 2>&1";
    if (std::system(cmd.c_str()) != 0) {  // e.g. no lz4 command (scripts/setup.sh installs it): a failure
      reason = "FAILED: " + cmd;
      return std::string();
    }
    return out;
  }();
  *why = reason;
  return dir;
}

#define REQUIRE_CLIENT(dir)                                          \
  std::string why;                                                   \
  const std::string& dir = ClientBags(&why);                         \
  ASSERT_EQ(why.rfind("FAILED", 0), std::string::npos) << why;       \
  if (dir.empty()) GTEST_SKIP() << "the MCAP client cannot run: " << why

const json& Expected(const std::string& dir) {
  static const json e = json::parse(ReadTextFile(dir + "/expected.json", "", "JSON"));
  return e;
}

// "" when `v` holds exactly the value the client wrote (`e`), else where it differs.
std::string Match(const MsgValue& v, const json& e, const std::string& at) {
  if (e.is_object() && e.contains("$bigint")) {
    const std::string want = e["$bigint"].get<std::string>();
    const std::string got = v.kind == MsgValue::kInt ? std::to_string(v.i)
                            : v.kind == MsgValue::kUint ? std::to_string(v.u) : "(not an integer)";
    return got == want ? "" : at + ": " + got + " != " + want;
  }
  if (e.is_object()) {
    if (v.kind != MsgValue::kStruct) return at + ": not a message";
    if (v.fields.size() != e.size()) return at + ": " + std::to_string(v.fields.size()) + " fields, wrote " + std::to_string(e.size());
    for (const auto& [k, x] : e.items()) {
      const MsgValue* f = v.Field(k);
      if (!f) return at + "." + k + ": missing";
      if (std::string m = Match(*f, x, at + "." + k); !m.empty()) return m;
    }
    return "";
  }
  if (e.is_array()) {
    if (v.kind != MsgValue::kArray || v.items.size() != e.size()) return at + ": not an array of " + std::to_string(e.size());
    for (size_t k = 0; k < e.size(); ++k)
      if (std::string m = Match(v.items[k], e[k], at + "[" + std::to_string(k) + "]"); !m.empty()) return m;
    return "";
  }
  if (e.is_string()) return v.kind == MsgValue::kString && v.s == e.get<std::string>() ? "" : at + ": '" + v.s + "'";
  if (e.is_boolean()) return v.kind == MsgValue::kBool && (v.i != 0) == e.get<bool>() ? "" : at + ": bool";
  if (e.is_number_integer()) {
    const bool same = e.is_number_unsigned() ? (v.kind == MsgValue::kUint && v.u == e.get<uint64_t>()) ||
                                                   (v.kind == MsgValue::kInt && v.i >= 0 &&
                                                    static_cast<uint64_t>(v.i) == e.get<uint64_t>())
                                             : (v.kind == MsgValue::kInt && v.i == e.get<int64_t>());
    // A float field holding an integral value (JSON writes 3.0 as 3).
    if (same || (v.kind == MsgValue::kFloat && v.f == e.get<double>())) return "";
    return at + ": " + std::to_string(v.Number()) + " != " + e.dump();
  }
  if (e.is_number_float()) return v.kind == MsgValue::kFloat && v.f == e.get<double>() ? "" : at + ": float " + std::to_string(v.f) + " != " + e.dump();
  return at + ": unexpected " + e.dump();
}


uint64_t Big(const json& e) { return std::stoull(e["$bigint"].get<std::string>()); }

// Every message of every topic of `r` is exactly what the client wrote.
void ExpectWritten(const McapRecord& r, const json& expected) {
  ASSERT_EQ(r.channels.size(), expected["topics"].size());
  for (const auto& [topic, msgs] : expected["topics"].items()) {
    const int c = r.Find(topic);
    ASSERT_GE(c, 0) << topic;
    std::vector<const McapMessage*> got;
    for (const McapMessage& m : r.messages)
      if (m.channel == static_cast<size_t>(c)) got.push_back(&m);
    ASSERT_EQ(got.size(), msgs.size()) << topic;
    const ChannelDecoder decode(r.channels[c], r.source, "test");
    for (size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k]->log_time, Big(msgs[k]["log_time"])) << topic << " " << k;
      EXPECT_EQ(got[k]->publish_time, Big(msgs[k]["publish_time"])) << topic << " " << k;
      EXPECT_EQ(got[k]->sequence, msgs[k]["sequence"].get<uint32_t>()) << topic << " " << k;
      EXPECT_EQ(Match(decode(*got[k], got[k]->where), msgs[k]["message"], topic), "") << "message " << k;
    }
  }
}

TEST(McapReader, ReadsExactlyWhatFoxglovesLibrariesWroteInEveryCompressionAndLayout) {
  REQUIRE_CLIENT(dir);
  for (const char* v : kVariants) {
    SCOPED_TRACE(v);
    const McapRecord r = ReadMcapRecord(dir + "/" + v + ".mcap");
    EXPECT_EQ(r.indexed, std::string(v).find("indexed") != std::string::npos);
    EXPECT_EQ(r.messages.size(), 399u);  // 300 + 76 + 5 + 15 + 3
    ExpectWritten(r, Expected(dir));
    EXPECT_EQ(r.channels[r.Find("/exo/probe")].schema.name, "exotwin_test/msg/Probe");
  }
}

// A topic filter keeps one topic's messages, and through the indexes the chunks without it are not
// read: the values are still exactly the client's, and the Statistics are checked per channel.
TEST(McapReader, ATopicFilterSkipsTheChunksWithoutItsTopic) {
  REQUIRE_CLIENT(dir);
  const auto probe = [](const std::string& topic) { return topic == "/exo/probe"; };
  for (const char* v : {"zstd_indexed", "zstd_linear", "plain"}) {
    SCOPED_TRACE(v);
    const McapRecord all = ReadMcapRecord(dir + "/" + v + ".mcap");
    const McapRecord one = ReadMcapRecord(dir + "/" + v + ".mcap", probe);
    EXPECT_EQ(one.channels.size(), all.channels.size());  // every channel listed
    json want = Expected(dir);
    for (auto it = want["topics"].begin(); it != want["topics"].end();)
      it = it.key() == "/exo/probe" ? std::next(it) : want["topics"].erase(it);
    ASSERT_EQ(one.messages.size(), 5u);
    const int c = one.Find("/exo/probe");
    const ChannelDecoder decode(one.channels[c], v, "test");
    for (size_t k = 0; k < 5; ++k)
      EXPECT_EQ(Match(decode(one.messages[k], ""), want["topics"]["/exo/probe"][k]["message"], "probe"), "");
    EXPECT_EQ(all.chunks_skipped, 0u);
    if (std::string(v) == "zstd_indexed") {
      EXPECT_GT(one.chunks_skipped, 0u);
      EXPECT_EQ(one.chunks_read + one.chunks_skipped, all.chunks_read);
    } else {
      EXPECT_EQ(one.chunks_skipped, 0u);  // no index: every chunk read
    }
  }
}

TEST(McapReader, ARosbag2FolderIsOneRecordOfItsFiles) {
  REQUIRE_CLIENT(dir);
  EXPECT_TRUE(IsBagPath(dir + "/rosbag2"));
  EXPECT_FALSE(IsBagPath(dir));  // a folder without metadata.yaml
  EXPECT_TRUE(IsBagPath(dir + "/plain.mcap"));
  EXPECT_FALSE(IsBagPath(dir + "/expected.json"));
  const testing::ScopedTempDir tmp("mcap_sniff");
  std::filesystem::copy_file(dir + "/plain.mcap", tmp.File("bag.bin"));
  EXPECT_TRUE(IsBagPath(tmp.File("bag.bin")));  // by its magic
  const McapRecord r = ReadMcapRecord(dir + "/rosbag2");
  EXPECT_FALSE(r.indexed);  // its second file has no summary
  ExpectWritten(r, Expected(dir));
  // Bad metadata: the key and the file named.
  const testing::ScopedTempDir bad("mcap_rosbag2");
  const auto meta = [&](const std::string& text) { std::ofstream(bad.File("metadata.yaml")) << text; };
  meta("rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths: [a.db3]\n");
  ExpectInputError([&] { ReadMcapRecord(bad.path()); },
                   {bad.File("metadata.yaml"), "storage_identifier", "'sqlite3', expected mcap"});
  meta("rosbag2_bagfile_information:\n  storage_identifier: mcap\n");
  ExpectInputError([&] { ReadMcapRecord(bad.path()); }, {"relative_file_paths", "missing or empty"});
  meta("rosbag2_bagfile_information:\n  relative_file_paths: [gone.mcap]\n");
  ExpectInputError([&] { ReadMcapRecord(bad.path()); }, {bad.File("gone.mcap") + ": cannot open MCAP file"});
  meta("a: [\n");
  ExpectInputError([&] { ReadMcapRecord(bad.path()); }, {bad.File("metadata.yaml"), "malformed YAML"});
}

std::string WriteMap(const testing::ScopedTempDir& tmp, const std::string& name, const std::string& text) {
  const std::string p = tmp.File(name);
  std::ofstream(p) << text;
  return p;
}

constexpr char kJointMap[] =
    "columns:\n"
    "  t:        {from: /exo/joint_states.header.stamp}\n"
    "  q_hip:    {from: \"/exo/joint_states.position[hip_flexion_joint]\"}\n"
    "  q_knee:   {from: \"/exo/joint_states.position[knee_joint]\"}\n"
    "  tau_hip:  {from: \"/exo/joint_states.effort[hip_flexion_joint]\", sign: -1}\n"
    "  tau_knee: {from: \"/exo/joint_states.effort[0]\", sign: -1}\n"
    "  qd_knee:  {from: \"/exo/joint_states.velocity[knee_joint]\"}\n"
    "  cmd_knee: {from: \"/exo/command.data[1]\"}\n";

void ExpectColumn(const MeasuredData& d, const std::string& name, const json& want, double tol) {
  const std::vector<double>* c = d.Column(name);
  ASSERT_NE(c, nullptr) << name;
  ASSERT_EQ(c->size(), want.size()) << name;
  for (size_t r = 0; r < c->size(); ++r) {
    if (tol == 0) ASSERT_EQ((*c)[r], want[r].get<double>()) << name << " row " << r;
    else ASSERT_NEAR((*c)[r], want[r].get<double>(), tol) << name << " row " << r;
  }
}

TEST(McapReader, TheColumnMapGivesTheRecordTheClientComputes) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_map");
  const std::string map = WriteMap(tmp, "map.yaml", kJointMap);
  const json& want = Expected(dir)["mapped"];
  std::vector<std::string> bags;
  for (const char* v : kVariants) bags.push_back(dir + "/" + v + ".mcap");
  bags.push_back(dir + "/rosbag2");
  for (const std::string& bag : bags) {
    SCOPED_TRACE(bag);
    MapReport report;
    const MeasuredData d = ReadMeasured(bag, map, 20, &report);
    EXPECT_EQ(report.rows_in, 300u);
    EXPECT_EQ(report.rows_out, 300u);
    EXPECT_NEAR(report.dt_median, 1e-3, 1e-15);
    EXPECT_LT(report.jitter, 1e-9);
    // t in int64 ns before seconds: the client's Number(ns - first) / 1e9, bit for bit.
    for (const char* c : {"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "qd_knee"}) ExpectColumn(d, c, want[c], 0);
    // Another topic, interpolated onto t's samples: the client interpolates in its own code.
    ExpectColumn(d, "cmd_knee", want["cmd_knee"], 1e-12);
  }
}

TEST(McapReader, LogTimeAndPublishTimeAsTheTimeBase) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_map");
  const json& want = Expected(dir)["mapped"];
  for (const char* which : {"log_time", "publish_time"}) {
    std::string text = kJointMap;
    text.replace(text.find("header.stamp"), 12, which);
    const MeasuredData d = ReadMeasured(dir + "/zstd_indexed.mcap", WriteMap(tmp, "m.yaml", text));
    // log and publish times are the stamps + a constant latency: the same t.
    ExpectColumn(d, "t", want["t"], 0);
    // The command topic is then placed by the same time, from the joint states' first.
    ExpectColumn(d, "cmd_knee", Expected(dir)["mapped_" + std::string(which)]["cmd_knee"], 1e-12);
  }
}

TEST(McapReader, JsonAndBigEndianTopicsThroughTheMap) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_map");
  const std::string map = WriteMap(tmp, "json.yaml",
                                   "columns:\n  t: {from: /exo/json_states.header.stamp}\n"
                                   "  q_hip: {from: \"/exo/json_states.position[hip]\"}\n"
                                   "  q_knee: {from: \"/exo/json_states.position[knee]\"}\n"
                                   "  tau_hip: {from: \"/exo/big_endian.values[0]\"}\n"
                                   "  tau_knee: {from: /exo/big_endian.level}\n");
  const MeasuredData d = ReadMeasured(dir + "/lz4_linear.mcap", map, 2);
  const json& js = Expected(dir)["topics"]["/exo/json_states"];
  ASSERT_EQ(d.size(), js.size());
  for (size_t k = 0; k < d.size(); ++k) {
    EXPECT_EQ(d.t()[k], static_cast<double>(k) * 20000000 / 1e9);
    EXPECT_EQ(d.q_hip()[k], js[k]["message"]["position"][0].get<double>());
    EXPECT_EQ(d.q_knee()[k], js[k]["message"]["position"][1].get<double>());
  }
  // The big-endian topic has header stamps 1733580001 s + 1000 k ns, 0.876543211 s after the JSON's
  // first: every JSON sample before it holds its first value.
  EXPECT_EQ(d.tau_hip().front(), 0.0);
  EXPECT_EQ(d.tau_knee().back(), -3.0);
}

// A topic of an encoding exotwin does not decode: its log_time can still be t's time base; a field of it
// is refused naming the encoding. (plain.mcap with its CRCs cleared: 0 = not computed.)
TEST(McapReader, ATopicOfAnotherEncodingGivesItsLogTimeButNoField) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_enc");
  std::string b = ReadBinaryFile(dir + "/plain.mcap", "");
  const std::string json_encoding("\x04\0\0\0json", 8);
  for (size_t at = 0; (at = b.find(json_encoding, at)) != std::string::npos; at += 8) b[at + 7] = 'x';
  const size_t footer = b.size() - 8 - 9 - 20;
  uint64_t summary = 0;
  for (int i = 8; i-- > 0;) summary = (summary << 8) | static_cast<unsigned char>(b[footer + 9 + i]);
  b.replace(summary - 4, 4, std::string(4, '\0'));     // Data End's CRC
  b.replace(footer + 9 + 16, 4, std::string(4, '\0'));  // the summary's
  std::ofstream(tmp.File("enc.mcap"), std::ios::binary) << b;
  std::string map = kJointMap;
  map.replace(map.find("/exo/joint_states.header.stamp"), 30, "/exo/json_states.log_time");
  const MeasuredData d = ReadMeasured(tmp.File("enc.mcap"), WriteMap(tmp, "m.yaml", map), 2);
  EXPECT_EQ(d.size(), 15u);
  EXPECT_EQ(d.t()[1], 0.02);
  map = kJointMap;
  map.replace(map.find("/exo/joint_states.header.stamp"), 30, "/exo/json_states.header.stamp");
  ExpectInputError([&] { ReadMeasured(tmp.File("enc.mcap"), WriteMap(tmp, "m.yaml", map), 2); },
                   {"m.yaml: columns.t.from (line 2): topic /exo/json_states of ", "holds messages encoded 'jsox'"});
}

// --- bad input -----------------------------------------------------------------------------------

std::string Bytes(const std::string& path) { return ReadBinaryFile(path, ""); }

void Spit(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

TEST(McapReader, NotMcapTruncatedAndCorruptFilesNameTheFileAndTheByte) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_bad");
  const std::string linear = Bytes(dir + "/none_linear.mcap");
  const std::string indexed = Bytes(dir + "/none_indexed.mcap");
  ExpectInputError([&] { ParseMcap("t,q_hip\n0,1\n", "x.mcap"); }, {"x.mcap: byte 0: not an MCAP file"});
  ExpectInputError([&] { ParseMcap("", "x.mcap"); }, {"x.mcap: byte 0: not an MCAP file"});
  // Cut: no footer, read linearly until the cut.
  for (const std::string* b : {&linear, &indexed})
    ExpectInputError([&] { ParseMcap(b->substr(0, b->size() * 3 / 5), "cut.mcap"); }, {"cut.mcap: byte ", "truncated"});
  ExpectInputError([&] { ParseMcap(linear.substr(0, linear.size() - 8), "cut.mcap"); }, {"cut.mcap: byte ", "truncated"});
  // A byte of a message inside an uncompressed chunk: the chunk's CRC.
  std::string bad = linear;
  const size_t at = bad.find("hip_flexion_joint");
  ASSERT_NE(at, std::string::npos);
  bad[at] = 'H';
  ExpectInputError([&] { ParseMcap(bad, "crc.mcap"); }, {"crc.mcap: byte ", "Chunk record", "uncompressed CRC"});
  // A byte of the header record (outside every chunk): the data section's CRC in Data End.
  bad = linear;
  const size_t lib = bad.find("exotwin tests/mcap_client");
  bad[lib] = 'E';
  ExpectInputError([&] { ParseMcap(bad, "crc.mcap"); }, {"crc.mcap: byte ", "Data End record", "data section CRC"});
  // A byte of the summary: the footer's summary CRC.
  bad = indexed;
  const size_t schema_in_summary = bad.rfind("sensor_msgs/msg/JointState");
  bad[schema_in_summary] = 'S';
  ExpectInputError([&] { ParseMcap(bad, "sum.mcap"); }, {"sum.mcap: byte ", "Footer record: summary CRC"});
  // A compressed chunk's bytes: zstd refuses them, or they decompress to bytes of another CRC.
  bad = Bytes(dir + "/zstd_linear.mcap");
  for (size_t k = 400; k < 420; ++k) bad[k] = static_cast<char>(bad[k] ^ 0x5A);
  ExpectInputError([&] { ParseMcap(bad, "z.mcap"); }, {"z.mcap: byte ", "Chunk record"});
  bad = Bytes(dir + "/lz4_linear.mcap");
  for (size_t k = 400; k < 420; ++k) bad[k] = static_cast<char>(bad[k] ^ 0x5A);
  ExpectInputError([&] { ParseMcap(bad, "l.mcap"); }, {"l.mcap: byte ", "Chunk record"});
  // An unknown compression.
  bad = Bytes(dir + "/zstd_linear.mcap");
  const size_t z = bad.find(std::string("\x04\0\0\0zstd", 8));
  ASSERT_NE(z, std::string::npos);
  bad[z + 7] = 'x';
  ExpectInputError([&] { ParseMcap(bad, "u.mcap"); }, {"u.mcap: byte ", "unknown compression 'zstx'"});
  // Through the command's entry: the path named.
  Spit(tmp.File("cut.mcap"), linear.substr(0, 5000));
  const std::string map = WriteMap(tmp, "map.yaml", kJointMap);
  ExpectInputError([&] { ReadMeasured(tmp.File("cut.mcap"), map); }, {tmp.File("cut.mcap") + ": byte ", "truncated"});
}

uint64_t Le64(const std::string& b, size_t at) {
  uint64_t v = 0;
  for (int i = 8; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

void PutLe64(std::string* b, size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) (*b)[at + i] = static_cast<char>(v >> (8 * i));
}

// The summary of an indexed file, its CRC cleared (0: not computed) so that a changed record is read:
// a Statistics count the file does not hold, a Chunk Index pointing off its chunk.
TEST(McapReader, TheSummarysIndexesAndStatisticsAreChecked) {
  REQUIRE_CLIENT(dir);
  const std::string good = Bytes(dir + "/lz4_indexed.mcap");
  const size_t footer = good.size() - 8 - 9 - 20;
  ASSERT_EQ(good[footer], static_cast<char>(mcap::kFooter));
  const size_t summary = Le64(good, footer + 9);
  const auto first = [&](uint8_t op) {
    for (size_t at = summary; at < footer; at += 9 + Le64(good, at + 1))
      if (static_cast<uint8_t>(good[at]) == op) return at;
    return std::string::npos;
  };
  std::string b = good;
  b.replace(footer + 9 + 16, 4, std::string(4, '\0'));
  EXPECT_EQ(ParseMcap(b, "f.mcap").messages.size(), 399u);  // no summary CRC: read as it is
  const size_t stats = first(mcap::kStatistics), index = first(mcap::kChunkIndex);
  ASSERT_NE(stats, std::string::npos);
  ASSERT_NE(index, std::string::npos);
  std::string bad = b;
  PutLe64(&bad, stats + 9, 400);
  ExpectInputError([&] { ParseMcap(bad, "s.mcap"); },
                   {"s.mcap: Statistics record: message_count 400 but the file holds 399"});
  bad = b;
  PutLe64(&bad, index + 9 + 16, Le64(b, index + 9 + 16) + 1);  // chunk_start_offset
  ExpectInputError([&] { ParseMcap(bad, "i.mcap"); },
                   {"i.mcap: byte " + std::to_string(index) + ": Chunk Index record", "do not hold a Chunk record"});
  // The footer's summary_start beyond the records.
  bad = good;
  PutLe64(&bad, footer + 9, footer + 1);
  ExpectInputError([&] { ParseMcap(bad, "o.mcap"); }, {"o.mcap: byte " + std::to_string(footer) + ": Footer record: summary_start"});
}

TEST(McapReader, AMapNamingWhatTheBagLacksNamesTheTopicAndTheField) {
  REQUIRE_CLIENT(dir);
  const testing::ScopedTempDir tmp("mcap_badmap");
  const std::string bag = dir + "/zstd_indexed.mcap";
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = kJointMap;
    text.replace(text.find(from), from.size(), to);
    return WriteMap(tmp, "m.yaml", text);
  };
  ExpectInputError([&] { ReadMeasured(bag, ""); }, {bag, "needs a column map"});
  ExpectInputError([&] { ReadMeasured(bag, with("/exo/command.data[1]", "/exo/cmd.data[1]")); },
                   {"m.yaml: columns.cmd_knee.from (line 8)", "'/exo/cmd.data[1]' names no topic of " + bag,
                    "/exo/joint_states", "/exo/command"});
  ExpectInputError([&] { ReadMeasured(bag, with("position[knee_joint]", "positon[knee_joint]")); },
                   {bag, "topic /exo/joint_states, message 1", "no field 'positon'", "header, name, position"});
  ExpectInputError([&] { ReadMeasured(bag, with("position[knee_joint]", "position[ankle]")); },
                   {"topic /exo/joint_states, message 1", "name 'ankle' is not in name [knee_joint, hip_flexion_joint]"});
  ExpectInputError([&] { ReadMeasured(bag, with("effort[0]", "effort[2]")); },
                   {"topic /exo/joint_states, message 1", "effort[2]: index 2 beyond its 2 elements"});
  ExpectInputError([&] { ReadMeasured(bag, with("/exo/command.data[1]", "/exo/probe.label")); },
                   {"topic /exo/probe, message 1", "label is a string, expected a number"});
  ExpectInputError([&] { ReadMeasured(bag, with("/exo/command.data[1]", "/exo/command.data[hip]")); },
                   {"topic /exo/command, message 1", "no array 'name' beside it"});
  ExpectInputError([&] { ReadMeasured(bag, with("/exo/joint_states.header.stamp", "/exo/joint_states.header.frame_id")); },
                   {"topic /exo/joint_states, message 1", "header.frame_id is not a time"});
  // Every message error names the byte offset of its record too.
  ExpectInputError([&] { ReadMeasured(bag, with("position[knee_joint]", "position[ankle]")); },
                   {bag + ": chunk at byte ", "of its records"});
}

// Every truncation and many single-byte changes of a small bag: parse or InputError, nothing else.
TEST(McapReader, NoByteStringCrashesTheReader) {
  REQUIRE_CLIENT(dir);
  for (const char* v : {"zstd_indexed", "lz4_linear", "plain"}) {
    const std::string b = Bytes(dir + "/" + v + ".mcap");
    const auto ok = [&](const std::string& bytes) {
      try {
        const McapRecord r = ParseMcap(bytes, "f.mcap");
        for (const McapMessage& m : r.messages) {
          try {
            ChannelDecoder(r.channels[m.channel], "f.mcap", "test")(m, m.where);
          } catch (const InputError&) {
          }
        }
      } catch (const InputError&) {
      }
    };
    for (size_t n = 0; n < b.size(); n += 97) ok(b.substr(0, n));
    for (size_t k = 0; k < b.size(); k += 31) {
      std::string c = b;
      c[k] = static_cast<char>(c[k] ^ 0xA5);
      ok(c);
    }
  }
}

}  // namespace
}  // namespace exotwin
