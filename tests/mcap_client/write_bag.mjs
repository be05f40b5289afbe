// The independent client of exotwin's bag reader (issue 65): Foxglove's own libraries (@mcap/core,
// @foxglove/rosmsg, @foxglove/rosmsg2-serialization, @foxglove/cdr, wasm-zstd) write ROS 2 bags, and
// what was written goes to expected.json for the C++ test (tests/formats/mcap_reader_test.cc) to
// compare exotwin's reading with. lz4 chunks: the reference `lz4` command (LZ4 frame format), since
// @foxglove/wasm-lz4 only decompresses.
//
// Usage:
//   node write_bag.mjs variants OUTDIR
//     OUTDIR/<compression>_<layout>.mcap for compression none, zstd, lz4 and layout indexed (chunks,
//     chunk and message indexes, statistics, summary offsets) or linear (chunks, no summary); plain.mcap
//     (no chunks, a summary without chunk indexes); rosbag2/ (metadata.yaml and two .mcap files
//     splitting the messages); expected.json. Every file holds the same messages on five topics:
//     /exo/joint_states (sensor_msgs/msg/JointState), /exo/command (std_msgs/msg/Float64MultiArray,
//     at another rate, no header), /exo/probe (a message type exotwin has never seen: nested, arrays,
//     bounded arrays and strings, constants, a default), /exo/json_states (json, jsonschema) and
//     /exo/big_endian (CDR big-endian, written field by field with @foxglove/cdr).
//   node write_bag.mjs fuzz-seeds OUTDIR
//     The fuzz target's seeds (fuzz/corpus/fuzz_mcap): small bags of every topic, no chunks / zstd
//     without a summary / lz4 with indexes, one cut short, one with a bad data-section CRC.
//   node write_bag.mjs from-csv DATA.csv OUT.mcap OUT.csv
//     The measured-data CSV as a JointState bag (names hip, knee; position q_*, velocity qd_* when
//     present, effort -tau_*; header.stamp = 1733580000.123456789 s + t), zstd chunks with indexes;
//     and OUT.csv: the same record with t = the stamp's offset in ns / 1e9 (the bag's own times).
import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { CdrWriter, EncapsulationKind } from "@foxglove/cdr";
import * as zstd from "@foxglove/wasm-zstd";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";

const SEP = "=".repeat(80);
const TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";

// The schema texts as rosbag2 stores them (the main definition, then each dependency after a line of '=').
const JOINT_STATE = [
  "# This is a message that holds data to describe the state of a set of torque controlled joints.\n" +
    "std_msgs/Header header\n\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
  HEADER, TIME].join(SEP + "\n");
const MULTI_ARRAY = [
  "MultiArrayLayout  layout        # specification of data layout\nfloat64[]         data          # array of data\n",
  "MSG: std_msgs/MultiArrayLayout\nMultiArrayDimension[] dim # Array of dimension properties\n" +
    "uint32 data_offset        # padding elements at front of data\n",
  "MSG: std_msgs/MultiArrayDimension\nstring label   # label of given dimension\nuint32 size    # size of given dimension\n" +
    "uint32 stride  # stride of given dimension\n"].join(SEP + "\n");
const PROBE = [
  "# A probe exotwin has never seen: every kind of field.\n" +
    "uint8 MODE_A=1\nstring GREETING=\"hi # not a comment\"\n" +
    "std_msgs/Header header\nstring label\nint8 small\nuint16 code\nfloat32 gain\nint64 big\nuint64 huge\n" +
    "bool flag\nbyte raw\nchar letter\nint16 neg\nuint32 count\nint32 offset\n" +
    "float64[3] triple\nSample[] samples\nSample[<=4] bounded\nstring<=16[] tags\nuint8[] blob\n" +
    "float64 scale 2.5   # a default value\nstring<=8 short_name\nbuiltin_interfaces/Duration span\n",
  "MSG: exotwin_test/Sample\nstring name\nfloat64 value\nint32[] counts\nEmpty nothing\n",
  "MSG: exotwin_test/Empty\n",
  HEADER, TIME, "MSG: builtin_interfaces/Duration\nint32 sec\nuint32 nanosec\n"].join(SEP + "\n");
const JSON_SCHEMA = JSON.stringify({
  type: "object",
  properties: {
    header: { type: "object", properties: { stamp: { type: "object", properties: { sec: { type: "integer" }, nanosec: { type: "integer" } } }, frame_id: { type: "string" } } },
    name: { type: "array", items: { type: "string" } },
    position: { type: "array", items: { type: "number" } },
  },
});
const BIG_ENDIAN = "std_msgs/Header header\nfloat64[] values\nint16 level\n" + SEP + "\n" + HEADER + SEP + "\n" + TIME;

const EPOCH_NS = 1733580000123456789n;  // 2024-12-07T14:00:00.123456789Z

function writerOf(text) {
  return new MessageWriter(parse(text, { ros2: true }));
}

// JSON with bigints as {"$bigint": "digits"}, byte arrays as arrays of numbers.
function toJson(value) {
  return JSON.stringify(value, (_k, v) =>
    (typeof v === "bigint" ? { $bigint: v.toString() } : v instanceof Uint8Array ? Array.from(v) : v), 1);
}

// Deterministic, not round numbers: every bit of a float64 counts.
function jointMessage(i) {
  const t = i / 1000;
  return {
    header: { stamp: { sec: Number((EPOCH_NS + BigInt(i) * 1000000n) / 1000000000n),
                       nanosec: Number((EPOCH_NS + BigInt(i) * 1000000n) % 1000000000n) },
              frame_id: "exo" },
    name: ["knee_joint", "hip_flexion_joint"],  // knee first: [NAME] must find each
    position: [-0.6 + 0.4 * Math.sin(2 * Math.PI * 0.9 * t + 0.3), 0.3 * Math.sin(2 * Math.PI * 1.3 * t)],
    velocity: [0.4 * 2 * Math.PI * 0.9 * Math.cos(2 * Math.PI * 0.9 * t + 0.3), 0.39 * 2 * Math.PI * Math.cos(2 * Math.PI * 1.3 * t)],
    effort: [3.1 * Math.sin(2 * Math.PI * 0.7 * t) - 1 / 3, -7.25 * Math.cos(2 * Math.PI * 1.1 * t) + Math.E],
  };
}

function commandMessage(k) {
  const t = k / 250;
  return {
    layout: { dim: [{ label: "joint", size: 2, stride: 2 }], data_offset: 0 },
    data: [0.1 * Math.cos(2 * Math.PI * 0.5 * t), 2.5 * Math.sin(2 * Math.PI * 0.8 * t) + 0.125],
  };
}

function probeMessage(k) {
  return {
    // ASCII: @foxglove/cdr's CdrWriter.string counts UTF-16 code units, not UTF-8 bytes (the JSON
    // topic carries the non-ASCII text).
    header: { stamp: { sec: 1733580000 + k, nanosec: 999999999 - k }, frame_id: `probe ${k}` },
    label: "label " + "x".repeat(k),
    small: -128 + k,
    code: 65535 - k,
    gain: Math.fround(0.1 * (k + 1)),
    big: -9007199254740993n - BigInt(k),  // beyond 2^53: exactly as int64
    huge: 18446744073709551615n - BigInt(k),
    flag: k % 2 === 1,
    raw: 255 - k,
    letter: 65 + k,
    neg: -32768 + k,
    count: 4294967295 - k,
    offset: -2147483648 + k,
    triple: [k + 0.5, -k - 0.25, Math.PI * k],
    samples: Array.from({ length: k }, (_, j) => ({ name: `s${j}`, value: j / 7, counts: Array.from({ length: j }, (_, m) => m - 3), nothing: {} })),
    bounded: Array.from({ length: Math.min(k, 4) }, (_, j) => ({ name: "", value: -j, counts: [], nothing: {} })),
    tags: k === 0 ? [] : ["alpha", "", "sixteen_chars_ok".slice(0, 16)],
    blob: new Uint8Array(Array.from({ length: 3 * k + 1 }, (_, j) => (j * 37 + k) & 255)),
    scale: 2.5 + k,
    short_name: "eight_ch".slice(0, 8 - k),
    span: { sec: -k, nanosec: 500000000 },
  };
}

function jsonMessage(k) {
  const ns = EPOCH_NS + BigInt(k) * 20000000n;
  return {
    header: { stamp: { sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) }, frame_id: "jsön ✓" },
    name: ["hip", "knee"],
    position: [k * 0.01 + 1 / 3, -k * 0.02 - 0.1],
  };
}

function bigEndianMessage(k) {
  return { header: { stamp: { sec: 1733580001, nanosec: 1000 * k }, frame_id: "be" }, values: [k / 3, -1e-300 * k, 1e300], level: -3 + k };
}

// Written field by field in big-endian CDR (the rosmsg2 writer only writes little-endian).
function bigEndianBytes(m) {
  const w = new CdrWriter({ kind: EncapsulationKind.CDR_BE });
  w.int32(m.header.stamp.sec);
  w.uint32(m.header.stamp.nanosec);
  w.string(m.header.frame_id);
  w.sequenceLength(m.values.length);
  for (const v of m.values) w.float64(v);
  w.int16(m.level);
  return w.data;
}

// Every topic's messages in log-time order: [{topic, logTime, publishTime, sequence, message, data}].
function allMessages(n = { joint: 300, command: 76, probe: 5, json: 15, be: 3 }) {
  const out = [];
  const joint = writerOf(JOINT_STATE), command = writerOf(MULTI_ARRAY), probe = writerOf(PROBE);
  for (let i = 0; i < n.joint; ++i) {
    const m = jointMessage(i);
    const stamp = EPOCH_NS + BigInt(i) * 1000000n;
    out.push({ topic: "/exo/joint_states", logTime: stamp + 200000n, publishTime: stamp + 100000n, sequence: i,
               message: m, data: joint.writeMessage(m) });
  }
  for (let k = 0; k < n.command; ++k) {  // 250 Hz from 0.5 ms after the first joint state
    const m = commandMessage(k);
    const t = EPOCH_NS + 500000n + BigInt(k) * 4000000n;
    out.push({ topic: "/exo/command", logTime: t, publishTime: t, sequence: k, message: m, data: command.writeMessage(m) });
  }
  for (let k = 0; k < n.probe; ++k) {
    const m = probeMessage(k);
    const t = EPOCH_NS + BigInt(k) * 50000000n + 7n;
    out.push({ topic: "/exo/probe", logTime: t, publishTime: t - 1n, sequence: 1000 + k, message: m, data: probe.writeMessage(m) });
  }
  for (let k = 0; k < n.json; ++k) {
    const m = jsonMessage(k);
    const t = EPOCH_NS + BigInt(k) * 20000000n + 3n;
    out.push({ topic: "/exo/json_states", logTime: t, publishTime: t, sequence: k, message: m,
               data: new TextEncoder().encode(JSON.stringify(m)) });
  }
  for (let k = 0; k < n.be; ++k) {
    const m = bigEndianMessage(k);
    const t = EPOCH_NS + BigInt(k) * 100000000n + 11n;
    out.push({ topic: "/exo/big_endian", logTime: t, publishTime: t, sequence: k, message: m, data: bigEndianBytes(m) });
  }
  out.sort((a, b) => (a.logTime < b.logTime ? -1 : a.logTime > b.logTime ? 1 : 0));
  return out;
}

const TOPICS = [
  { topic: "/exo/joint_states", name: "sensor_msgs/msg/JointState", encoding: "ros2msg", text: JOINT_STATE, messageEncoding: "cdr" },
  { topic: "/exo/command", name: "std_msgs/msg/Float64MultiArray", encoding: "ros2msg", text: MULTI_ARRAY, messageEncoding: "cdr" },
  { topic: "/exo/probe", name: "exotwin_test/msg/Probe", encoding: "ros2msg", text: PROBE, messageEncoding: "cdr" },
  { topic: "/exo/json_states", name: "exotwin_test/JsonStates", encoding: "jsonschema", text: JSON_SCHEMA, messageEncoding: "json" },
  { topic: "/exo/big_endian", name: "exotwin_test/msg/BigEndian", encoding: "ros2msg", text: BIG_ENDIAN, messageEncoding: "cdr" },
];

function compressor(compression) {
  if (compression === "zstd") return (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) });
  if (compression === "lz4")
    return (d) => ({ compression: "lz4", compressedData: new Uint8Array(execFileSync("lz4", ["-q", "-z", "-c"], { input: d })) });
  return undefined;
}

// Writes `messages` (of `topics`) to `file`. layout: indexed | linear | plain.
async function writeBag(file, messages, topics, compression, layout) {
  const parts = [];
  let size = 0n;
  const writable = { position: () => size, write: async (b) => { parts.push(Buffer.from(b)); size += BigInt(b.byteLength); } };
  const indexed = layout !== "linear";
  const writer = new McapWriter({
    writable,
    useChunks: layout !== "plain",
    chunkSize: 4096,  // several chunks per file
    compressChunk: compressor(compression),
    useStatistics: indexed, useSummaryOffsets: indexed, useChunkIndex: indexed, useMessageIndex: indexed,
    useAttachmentIndex: indexed, useMetadataIndex: indexed, repeatSchemas: indexed, repeatChannels: indexed,
  });
  await writer.start({ profile: "ros2", library: "exotwin tests/mcap_client (@mcap/core 2.2.2)" });
  const channel = new Map();
  for (const t of topics) {
    const schemaId = await writer.registerSchema({ name: t.name, encoding: t.encoding, data: new TextEncoder().encode(t.text) });
    channel.set(t.topic, await writer.registerChannel({ topic: t.topic, schemaId, messageEncoding: t.messageEncoding, metadata: new Map() }));
  }
  for (const m of messages)
    await writer.addMessage({ channelId: channel.get(m.topic), sequence: m.sequence, logTime: m.logTime, publishTime: m.publishTime, data: m.data });
  await writer.end();
  fs.writeFileSync(file, Buffer.concat(parts));
}

// Linear interpolation of (x, y) at xq, held at the ends: the expected value of a column from another topic.
function interpolate(x, y, xq) {
  if (xq <= x[0]) return y[0];
  if (xq >= x[x.length - 1]) return y[y.length - 1];
  let j = 0;
  while (x[j + 1] < xq) ++j;
  const w = (xq - x[j]) / (x[j + 1] - x[j]);
  return y[j] + w * (y[j + 1] - y[j]);
}

async function variants(dir) {
  await zstd.isLoaded;
  fs.mkdirSync(dir, { recursive: true });
  const messages = allMessages();
  for (const compression of ["none", "zstd", "lz4"])
    for (const layout of ["indexed", "linear"])
      await writeBag(path.join(dir, `${compression}_${layout}.mcap`), messages, TOPICS, compression, layout);
  await writeBag(path.join(dir, "plain.mcap"), messages, TOPICS, "none", "plain");
  // A rosbag2 folder: the messages split in two files, each with every channel.
  const bag2 = path.join(dir, "rosbag2");
  fs.mkdirSync(bag2, { recursive: true });
  const half = Math.floor(messages.length / 2);
  await writeBag(path.join(bag2, "rosbag2_0.mcap"), messages.slice(0, half), TOPICS, "zstd", "indexed");
  await writeBag(path.join(bag2, "rosbag2_1.mcap"), messages.slice(half), TOPICS, "lz4", "linear");
  fs.writeFileSync(path.join(bag2, "metadata.yaml"),
    "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n" +
    "  relative_file_paths:\n    - rosbag2_0.mcap\n    - rosbag2_1.mcap\n" +
    `  message_count: ${messages.length}\n`);
  // What was written, per topic in log-time order; and the columns of the test's map.
  const expected = { topics: {}, mapped: {} };
  for (const m of messages)
    (expected.topics[m.topic] ??= []).push({ log_time: m.logTime, publish_time: m.publishTime, sequence: m.sequence, message: m.message });
  const joints = expected.topics["/exo/joint_states"], commands = expected.topics["/exo/command"];
  const stampNs = (s) => BigInt(s.sec) * 1000000000n + BigInt(s.nanosec);
  const origin = stampNs(joints[0].message.header.stamp);
  const t = joints.map((j) => Number(stampNs(j.message.header.stamp) - origin) / 1e9);
  const tc = commands.map((c) => Number(c.log_time - origin) / 1e9);
  const cmd = commands.map((c) => c.message.data[1]);
  // With t from log_time (publish_time): the origin is the first joint state's log (publish) time,
  // the commands placed by theirs.
  for (const which of ["log_time", "publish_time"]) {
    const o = joints[0][which];
    const x = commands.map((c) => Number(c[which] - o) / 1e9);
    expected[`mapped_${which}`] = { cmd_knee: joints.map((j) => interpolate(x, cmd, Number(j[which] - o) / 1e9)) };
  }
  expected.mapped = {
    t,
    q_hip: joints.map((j) => j.message.position[1]),
    q_knee: joints.map((j) => j.message.position[0]),
    tau_hip: joints.map((j) => -j.message.effort[1]),
    tau_knee: joints.map((j) => -j.message.effort[0]),
    qd_knee: joints.map((j) => j.message.velocity[0]),
    cmd_knee: t.map((x) => interpolate(tc, cmd, x)),
  };
  fs.writeFileSync(path.join(dir, "expected.json"), toJson(expected));
}

// The measured-data CSV as a bag, and the CSV of the bag's own times.
async function fromCsv(csvPath, bagPath, outCsv) {
  await zstd.isLoaded;
  const lines = fs.readFileSync(csvPath, "utf8").split(/\r?\n/).filter((l) => l.trim() !== "" && !l.startsWith("#"));
  const names = lines[0].split(",").map((s) => s.trim());
  const rows = lines.slice(1).map((l) => l.split(",").map(Number));
  const col = (n) => names.indexOf(n);
  const joint = writerOf(JOINT_STATE);
  const messages = [];
  const tOut = [];
  for (let r = 0; r < rows.length; ++r) {
    const v = rows[r];
    const offset = BigInt(Math.round(v[col("t")] * 1e9)) - BigInt(Math.round(rows[0][col("t")] * 1e9));
    const stamp = EPOCH_NS + offset;
    tOut.push(Number(offset) / 1e9);
    const m = {
      header: { stamp: { sec: Number(stamp / 1000000000n), nanosec: Number(stamp % 1000000000n) }, frame_id: "exo" },
      name: ["hip", "knee"],
      position: [v[col("q_hip")], v[col("q_knee")]],
      velocity: col("qd_hip") >= 0 ? [v[col("qd_hip")], v[col("qd_knee")]] : [],
      effort: [-v[col("tau_hip")], -v[col("tau_knee")]],
    };
    messages.push({ topic: "/exo/joint_states", logTime: stamp, publishTime: stamp, sequence: r, message: m, data: joint.writeMessage(m) });
  }
  await writeBag(bagPath, messages, [TOPICS[0]], "zstd", "indexed");
  const out = [names.join(",")];
  for (let r = 0; r < rows.length; ++r) out.push(rows[r].map((x, c) => String(c === col("t") ? tOut[r] : x)).join(","));
  fs.writeFileSync(outCsv, out.join("\n") + "\n");
}

// The seed corpus of the fuzz target (fuzz/corpus/fuzz_mcap): small bags of every topic.
async function fuzzSeeds(dir) {
  await zstd.isLoaded;
  fs.mkdirSync(dir, { recursive: true });
  const messages = allMessages({ joint: 12, command: 3, probe: 2, json: 2, be: 1 });
  await writeBag(path.join(dir, "valid_plain.mcap"), messages, TOPICS, "none", "plain");
  await writeBag(path.join(dir, "valid_zstd_linear.mcap"), messages, TOPICS, "zstd", "linear");
  await writeBag(path.join(dir, "valid_lz4_indexed.mcap"), messages, TOPICS, "lz4", "indexed");
  const whole = fs.readFileSync(path.join(dir, "valid_plain.mcap"));
  fs.writeFileSync(path.join(dir, "invalid_truncated.mcap"), whole.subarray(0, Math.floor(whole.length * 0.6)));
  const flipped = Buffer.from(whole);
  flipped[flipped.indexOf("exotwin tests/mcap_client")] ^= 0x20;  // in the Header record: the data CRC
  fs.writeFileSync(path.join(dir, "invalid_bad_crc.mcap"), flipped);
}

const [mode, ...args] = process.argv.slice(2);
if (mode === "variants" && args.length === 1) await variants(args[0]);
else if (mode === "fuzz-seeds" && args.length === 1) await fuzzSeeds(args[0]);
else if (mode === "from-csv" && args.length === 3) await fromCsv(...args);
else {
  console.error("usage: node write_bag.mjs variants OUTDIR | from-csv DATA.csv OUT.mcap OUT.csv | fuzz-seeds OUTDIR");
  process.exit(2);
}
