// An independent reader for lidarloop's MCAP logs, built only on Foxglove's public libraries (the
// ones Foxglove Studio and Lichtblick use): the file is read twice, once through the summary and
// indexes (McapIndexedReader: footer, summary CRC, chunk and message indexes, chunk CRCs) and once
// record by record (McapStreamReader, chunk CRCs on), and every message is decoded with the ROS 2
// definition in its schema. Prints, as JSON: the header, message counts per topic, attachments,
// metadata, the first scan's stamp, fields and first and last points, and the first lost localizer status.
// Usage: node read_mcap.mjs FILE.mcap      Exit 1 (with a message on stderr) on any disagreement.
import { open, readFile } from "node:fs/promises";

import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

const path = process.argv[2];
if (!path) {
  console.error("usage: node read_mcap.mjs FILE.mcap");
  process.exit(2);
}

function fail(message) {
  console.error(`read_mcap.mjs: ${path}: ${message}`);
  process.exit(1);
}

const decompressHandlers = await loadDecompressHandlers();

// One decoder per schema; every message must decode to exactly its own length.
const readers = new Map();
function decode(schema, channel, data) {
  if (schema.encoding !== "ros2msg" || channel.messageEncoding !== "cdr")
    fail(`${channel.topic}: expected ros2msg/cdr, found ${schema.encoding}/${channel.messageEncoding}`);
  let reader = readers.get(schema.id);
  if (!reader) {
    reader = new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true }));
    readers.set(schema.id, reader);
  }
  const message = reader.readMessage(data);
  if (reader.lastReadHadTrailingBytes()) fail(`${channel.topic}: message has bytes its schema does not explain`);
  return message;
}

// PointCloud2 point `i` as { field: value } for every field, read as the field's datatype says.
function point(cloud, i) {
  const view = new DataView(cloud.data.buffer, cloud.data.byteOffset, cloud.data.byteLength);
  const base = i * cloud.point_step;
  const out = {};
  for (const f of cloud.fields) {
    const at = base + f.offset;
    switch (f.datatype) {
      case 1: out[f.name] = view.getInt8(at); break;
      case 2: out[f.name] = view.getUint8(at); break;
      case 3: out[f.name] = view.getInt16(at, true); break;
      case 4: out[f.name] = view.getUint16(at, true); break;
      case 5: out[f.name] = view.getInt32(at, true); break;
      case 6: out[f.name] = view.getUint32(at, true); break;
      case 7: out[f.name] = view.getFloat32(at, true); break;
      case 8: out[f.name] = view.getFloat64(at, true); break;
      default: fail(`unknown PointField datatype ${f.datatype}`);
    }
  }
  return out;
}

// 1. Indexed: what Foxglove does when it opens a file.
const handle = await open(path, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, length) => {
    const buffer = new Uint8Array(Number(length));
    const { bytesRead } = await handle.read(buffer, 0, buffer.length, Number(offset));
    if (bytesRead !== buffer.length) fail(`short read at ${offset}`);
    return buffer;
  },
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const indexedCounts = {};
for await (const message of indexed.readMessages({ validateCrcs: true })) {
  const channel = indexed.channelsById.get(message.channelId);
  decode(indexed.schemasById.get(channel.schemaId), channel, message.data);
  indexedCounts[channel.topic] = (indexedCounts[channel.topic] ?? 0) + 1;
}
const metadata = {};
for await (const m of indexed.readMetadata()) metadata[m.name] = Object.fromEntries(m.metadata);
const attachments = [];
for await (const a of indexed.readAttachments({ validateCrcs: true }))
  attachments.push({ name: a.name, mediaType: a.mediaType, size: a.data.byteLength });
await handle.close();

// 2. Streaming, record by record: what a player reading a file front to back does.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(await readFile(path));
const schemas = new Map(), channels = new Map(), counts = {};
let header, firstScan, lostStatus, statistics, records = 0, sawFooter = false;
for (let record; (record = stream.nextRecord()); ) {
  ++records;
  switch (record.type) {
    case "Header": header = { profile: record.profile, library: record.library }; break;
    case "Schema": schemas.set(record.id, record); break;
    case "Channel": channels.set(record.id, record); break;
    case "Statistics": statistics = record; break;
    case "Footer": sawFooter = true; break;
    case "Message": {
      const channel = channels.get(record.channelId);
      if (!channel) fail(`message on undefined channel ${record.channelId}`);
      const message = decode(schemas.get(channel.schemaId), channel, record.data);
      counts[channel.topic] = (counts[channel.topic] ?? 0) + 1;
      // The first lost localizer status (diagnostic_msgs/msg/DiagnosticArray), as decoded.
      if (!lostStatus && channel.topic === "/localizer/status" && message.status[0]?.level === 2) {
        const s = message.status[0];
        lostStatus = {
          stamp: { sec: message.header.stamp.sec, nanosec: message.header.stamp.nanosec },
          level: s.level,
          name: s.name,
          message: s.message,
          hardware_id: s.hardware_id,
          values: Object.fromEntries(s.values.map((kv) => [kv.key, kv.value])),
        };
      }
      if (!firstScan && channel.topic === "/lidar/points") {
        const n = message.width * message.height;
        firstScan = {
          stamp: { sec: message.header.stamp.sec, nanosec: message.header.stamp.nanosec },
          frame_id: message.header.frame_id,
          width: message.width,
          point_step: message.point_step,
          fields: message.fields.map((f) => f.name),
          first: point(message, 0),
          last: point(message, n - 1),
        };
      }
      break;
    }
  }
}
if (!stream.done()) fail("the stream reader did not reach the end of the file");
if (!sawFooter) fail("no footer");

// The two passes and the summary's statistics must agree.
const same = (a, b) => JSON.stringify(Object.entries(a).sort()) === JSON.stringify(Object.entries(b).sort());
if (!same(counts, indexedCounts)) fail(`indexed and streamed counts differ: ${JSON.stringify([indexedCounts, counts])}`);
const statisticsCounts = {};
for (const [id, n] of statistics.channelMessageCounts) statisticsCounts[channels.get(id).topic] = Number(n);
if (!same(counts, statisticsCounts)) fail(`Statistics disagree with the messages: ${JSON.stringify(statisticsCounts)}`);

console.log(
  JSON.stringify(
    {
      header,
      records,
      chunks: indexed.chunkIndexes.length,
      counts,
      attachments,
      metadata,
      first_scan: firstScan ?? null,
      lost_status: lostStatus ?? null,
    },
    null,
    2,
  ),
);
