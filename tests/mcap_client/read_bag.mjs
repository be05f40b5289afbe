// Reads an MCAP file (a ROS 2 bag exotwin wrote) with Foxglove's own libraries, as an independent
// client: McapIndexedReader (summary CRC, chunk CRCs, messages found through the chunk and message
// indexes) and McapStreamReader (every record in file order, chunk CRCs), the data section's CRC
// recomputed against the data-end record, every message decoded with the rosmsg2 deserializer built
// from the file's own schema text. Exits 1 (message on stderr) on any inconsistency.
//
// usage: node read_bag.mjs FILE.mcap [--summary]
// Prints JSON: {profile, library, metadata: {name: {key: value}}, statistics: {...},
//   topics: {TOPIC: {schema, encoding, count, messages: [{log_time, publish_time, message}]}}}
// (log_time / publish_time: ns as decimal strings; typed arrays as arrays; --summary: no messages).
import { readFile } from "node:fs/promises";

import { crc32 } from "@foxglove/crc";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import lz4 from "@foxglove/wasm-lz4";
import * as zstd from "@foxglove/wasm-zstd";

function fail(what) {
  process.stderr.write(`read_bag: ${what}\n`);
  process.exit(1);
}

const args = process.argv.slice(2);
const path = args.find((a) => !a.startsWith("--"));
const summaryOnly = args.includes("--summary");
if (!path) fail("usage: node read_bag.mjs FILE.mcap [--summary]");

await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
  lz4: (buffer, size) => lz4(buffer, Number(size)),
};

const bytes = new Uint8Array(await readFile(path));
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};

// 1. Indexed: summary (its CRC checked by Initialize), then every message through the indexes.
let indexed;
try {
  indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
} catch (e) {
  fail(`McapIndexedReader: ${e.message}`);
}
if (indexed.footer.summaryCrc === 0) fail("the footer has no summary CRC");
if (indexed.chunkIndexes.length === 0) fail("no chunk indexes");
const dataEndOffset = Number(indexed.footer.summaryStart) - (1 + 8 + 4);
if (bytes[dataEndOffset] !== 0x0f) fail(`no data-end record before the summary (byte ${dataEndOffset})`);
if (indexed.dataSectionCrc === undefined) fail("the data-end record has no CRC");
const dataCrc = crc32(bytes.subarray(0, dataEndOffset));
if (dataCrc !== indexed.dataSectionCrc)
  fail(`data section CRC ${dataCrc}, the data-end record says ${indexed.dataSectionCrc}`);

const readers = new Map();  // schema id -> MessageReader from the file's schema text
for (const [id, schema] of indexed.schemasById) {
  if (schema.encoding !== "ros2msg") fail(`schema ${schema.name}: encoding ${schema.encoding}, expected ros2msg`);
  const text = new TextDecoder().decode(schema.data);
  readers.set(id, new MessageReader(parse(text, { ros2: true })));
}

function plain(v) {  // typed arrays and bigints as JSON values
  if (ArrayBuffer.isView(v)) return Array.from(v);
  if (typeof v === "bigint") return v.toString();
  if (Array.isArray(v)) return v.map(plain);
  if (v && typeof v === "object") return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, plain(x)]));
  return v;
}

const topics = {};
for (const [id, channel] of indexed.channelsById) {
  if (channel.messageEncoding !== "cdr") fail(`${channel.topic}: message encoding ${channel.messageEncoding}, expected cdr`);
  topics[channel.topic] = {
    schema: indexed.schemasById.get(channel.schemaId)?.name, encoding: channel.messageEncoding, count: 0, messages: [],
  };
}
const indexedList = [];
try {
  for await (const m of indexed.readMessages()) {
    const channel = indexed.channelsById.get(m.channelId);
    const message = readers.get(channel.schemaId).readMessage(m.data);
    const t = topics[channel.topic];
    ++t.count;
    if (!summaryOnly)
      t.messages.push({ log_time: m.logTime.toString(), publish_time: m.publishTime.toString(), message: plain(message) });
    indexedList.push(m);
  }
} catch (e) {
  fail(`McapIndexedReader.readMessages: ${e.message}`);
}

// 2. Streaming: every record in file order; the same messages as the indexes give.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(bytes);
const streamed = [];
let header, footer, dataEnd;
const metadata = {};
try {
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Message") streamed.push(r);
    else if (r.type === "Header") header = r;
    else if (r.type === "Footer") footer = r;
    else if (r.type === "DataEnd") dataEnd = r;
    else if (r.type === "Metadata") metadata[r.name] = Object.fromEntries(r.metadata);
  }
} catch (e) {
  fail(`McapStreamReader: ${e.message}`);
}
if (!stream.done()) fail("McapStreamReader: the file ends before its footer and magic");
if (!header || !footer || !dataEnd) fail("McapStreamReader: header, data end or footer missing");
if (dataEnd.dataSectionCrc !== dataCrc) fail("McapStreamReader: data-end CRC differs");
if (streamed.length !== indexedList.length)
  fail(`McapStreamReader read ${streamed.length} messages, the indexes ${indexedList.length}`);
// The indexed reader returns messages in log-time order (ties in file order), as they were written.
for (let i = 0; i < streamed.length; ++i) {
  const a = streamed[i], b = indexedList[i];
  if (a.channelId !== b.channelId || a.logTime !== b.logTime || a.sequence !== b.sequence ||
      Buffer.compare(Buffer.from(a.data), Buffer.from(b.data)) !== 0)
    fail(`message ${i}: the stream and the indexes disagree`);
}

// 3. Statistics and metadata index against what was read.
const st = indexed.statistics;
if (!st) fail("no statistics record");
if (st.messageCount !== BigInt(streamed.length)) fail(`statistics: ${st.messageCount} messages, read ${streamed.length}`);
for (const [id, channel] of indexed.channelsById)
  if ((st.channelMessageCounts.get(id) ?? 0n) !== BigInt(topics[channel.topic].count))
    fail(`statistics: ${channel.topic} count ${st.channelMessageCounts.get(id)}, read ${topics[channel.topic].count}`);
if (st.chunkCount !== indexed.chunkIndexes.length) fail("statistics: chunk count differs from the chunk indexes");
if (indexed.metadataIndexes.length !== Object.keys(metadata).length) fail("metadata indexes differ from the metadata records");
for (const mi of indexed.metadataIndexes) {
  const r = await indexed.readMetadata({ name: mi.name });  // through the metadata index
  for await (const m of r) if (JSON.stringify(Object.fromEntries(m.metadata)) !== JSON.stringify(metadata[mi.name]))
    fail(`metadata ${mi.name}: the index points elsewhere`);
}

process.stdout.write(JSON.stringify({
  profile: header.profile,
  library: header.library,
  metadata,
  statistics: {
    message_count: st.messageCount.toString(), schema_count: st.schemaCount, channel_count: st.channelCount,
    chunk_count: st.chunkCount, metadata_count: st.metadataCount,
    message_start_time: st.messageStartTime.toString(), message_end_time: st.messageEndTime.toString(),
    compression: [...new Set(indexed.chunkIndexes.map((c) => c.compression))],
  },
  topics,
}) + "\n");
