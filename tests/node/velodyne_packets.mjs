// Checks lidarloop's HDL-32E packets with code that is not ours:
//  1. every velodyne_msgs/msg/VelodyneScan of the log is decoded by Foxglove's @foxglove/velodyne-cloud
//     (HDL-32E calibration) into points, which must be the log's PointCloud2 of the same revolution:
//     the same count, and point for point (both in firing order) within 2 mm, equal intensity, and
//     the channel (velodyne-cloud's `ring` is the calibration's laser_id) the ring's firing slot;
//  2. the pcap from `lidarloop export --pcap` is parsed by the npm package pcap-parser: Ethernet,
//     IPv4 (header checksum), UDP; data packets on port 2368 must be the log's packets byte for byte
//     and in order, with their stamps as capture times; position packets on 8308 carry a $GPRMC with
//     a valid checksum, one per whole second of the capture.
// Usage: node velodyne_packets.mjs LOG.mcap CAPTURE.pcap     Exit 1 with a message on any disagreement.
import { readFile } from "node:fs/promises";
import { createRequire } from "node:module";

import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

const require = createRequire(import.meta.url);
const pcapParser = require("pcap-parser");
const { Calibration, Model, PointCloud, RawPacket, Transformer } = require("@foxglove/velodyne-cloud");

const [logPath, pcapPath] = process.argv.slice(2);
if (!logPath || !pcapPath) {
  console.error("usage: node velodyne_packets.mjs LOG.mcap CAPTURE.pcap");
  process.exit(2);
}
function fail(message) {
  console.error(`velodyne_packets.mjs: ${message}`);
  process.exit(1);
}

const kTolerance = 0.002;  // m, the brief's: a driver's point and ours agree to the distance unit
const kDataPort = 2368, kPositionPort = 8308;

// --- 1. The log: PointCloud2 and VelodyneScan messages in log order -------------------------------
const stream = new McapStreamReader({ decompressHandlers: await loadDecompressHandlers(), validateCrcs: true });
stream.append(await readFile(logPath));
const schemas = new Map(), channels = new Map(), readers = new Map();
const clouds = [], scans = [];
for (let record; (record = stream.nextRecord()); ) {
  if (record.type === "Schema") schemas.set(record.id, record);
  else if (record.type === "Channel") channels.set(record.id, record);
  else if (record.type === "Message") {
    const channel = channels.get(record.channelId);
    const schema = schemas.get(channel.schemaId);
    if (schema.name !== "sensor_msgs/msg/PointCloud2" && schema.name !== "velodyne_msgs/msg/VelodyneScan") continue;
    let reader = readers.get(schema.id);
    if (!reader) {
      reader = new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true }));
      readers.set(schema.id, reader);
    }
    const message = reader.readMessage(record.data);
    if (schema.name === "sensor_msgs/msg/PointCloud2") clouds.push(message);
    else scans.push(message);
  }
}
if (scans.length === 0) fail(`${logPath}: no VelodyneScan messages (recorded without --packets?)`);
if (scans.length !== clouds.length) fail(`${scans.length} VelodyneScan messages but ${clouds.length} PointCloud2`);

// Our ring (0 = lowest beam) of the laser in channel j: the HDL-32E fires the lower and upper banks
// alternately (calibration laser_id 0, 1, 2, ... = -30.67, -9.33, -29.33, ... deg).
const ringOfChannel = (j) => (j % 2 === 0 ? j / 2 : 16 + (j - 1) / 2);

const transformer = new Transformer(new Calibration(Model.HDL32E));
let points = 0, worst = 0, packetsInLog = 0;
const logPackets = [];
for (let k = 0; k < scans.length; ++k) {
  const scan = scans[k], cloud = clouds[k];
  const stampOf = (t) => t.sec + t.nanosec * 1e-9;
  const decoded = new PointCloud({ stamp: stampOf(scan.header.stamp), maxPoints: scan.packets.length * RawPacket.MAX_POINTS_PER_PACKET });
  for (const packet of scan.packets) {
    const raw = new RawPacket(packet.data);
    if (raw.inferModel() !== Model.HDL32E) fail(`scan ${k}: packet not recognised as an HDL-32E's`);
    transformer.unpack(raw, stampOf(scan.header.stamp), stampOf(packet.stamp), decoded);
    logPackets.push({ stamp: BigInt(packet.stamp.sec) * 1000000000n + BigInt(packet.stamp.nanosec), data: packet.data });
  }
  packetsInLog += scan.packets.length;
  const field = (name) => cloud.fields.find((f) => f.name === name);
  const [fx, fy, fz, fi, fr] = ["x", "y", "z", "intensity", "ring"].map(field);
  if (!fx || !fy || !fz || !fi || !fr) fail(`cloud ${k}: missing fields`);
  const view = new DataView(cloud.data.buffer, cloud.data.byteOffset, cloud.data.byteLength);
  const count = cloud.width * cloud.height;
  if (decoded.width !== count) fail(`scan ${k}: velodyne-cloud decodes ${decoded.width} points, the PointCloud2 has ${count}`);
  for (let i = 0; i < count; ++i) {
    const base = i * cloud.point_step;
    const ours = {
      x: view.getFloat32(base + fx.offset, true),
      y: view.getFloat32(base + fy.offset, true),
      z: view.getFloat32(base + fz.offset, true),
      intensity: view.getFloat32(base + fi.offset, true),
      ring: view.getUint16(base + fr.offset, true),
    };
    const theirs = decoded.point(i);
    const d = Math.hypot(ours.x - theirs.x, ours.y - theirs.y, ours.z - theirs.z);
    worst = Math.max(worst, d);
    if (!(d <= kTolerance))
      fail(`scan ${k} point ${i}: ours (${ours.x}, ${ours.y}, ${ours.z}), velodyne-cloud's (${theirs.x}, ${theirs.y}, ${theirs.z}): ${d} m apart`);
    if (ours.intensity !== theirs.intensity) fail(`scan ${k} point ${i}: intensity ${ours.intensity} vs ${theirs.intensity}`);
    if (ours.ring !== ringOfChannel(theirs.ring)) fail(`scan ${k} point ${i}: ring ${ours.ring} but channel ${theirs.ring}`);
  }
  points += count;
}

// --- 2. The capture ---------------------------------------------------------------------------------
function ipv4Checksum(bytes) {
  let sum = 0;
  for (let i = 0; i < bytes.length; i += 2) sum += (bytes[i] << 8) | bytes[i + 1];
  while (sum > 0xffff) sum = (sum & 0xffff) + (sum >>> 16);
  return ~sum & 0xffff;
}
function nmeaChecksumOk(sentence) {
  const m = /^\$([^*]*)\*([0-9A-F]{2})\r\n$/.exec(sentence);
  if (!m) return false;
  let sum = 0;
  for (const c of m[1]) sum ^= c.charCodeAt(0);
  return sum === parseInt(m[2], 16);
}

const capture = await new Promise((resolve, reject) => {
  const parser = pcapParser.parse(pcapPath);
  const out = { header: null, packets: [] };
  parser.on("globalHeader", (h) => (out.header = h));
  parser.on("packet", (p) => out.packets.push(p));
  parser.on("end", () => resolve(out));
  parser.on("error", reject);
});
if (capture.header.linkLayerType !== 1) fail(`pcap link type ${capture.header.linkLayerType}, expected 1 (Ethernet)`);
let data = 0, positions = 0, lastTime = -1n;
const positionTimes = [];
for (const [n, p] of capture.packets.entries()) {
  const f = p.data;
  if (f.readUInt16BE(12) !== 0x0800) fail(`frame ${n}: not IPv4`);
  const ip = f.subarray(14, 34);
  if (ip[0] !== 0x45 || ip[9] !== 17) fail(`frame ${n}: not a plain IPv4/UDP header`);
  if (ipv4Checksum(ip) !== 0) fail(`frame ${n}: IPv4 header checksum wrong`);
  if (ip.readUInt16BE(2) !== f.length - 14) fail(`frame ${n}: IPv4 total length ${ip.readUInt16BE(2)} vs frame ${f.length}`);
  const port = f.readUInt16BE(36), payload = f.subarray(42);
  if (f.readUInt16BE(38) !== payload.length + 8) fail(`frame ${n}: UDP length`);
  if (p.header.capturedLength !== f.length || p.header.originalLength !== f.length) fail(`frame ${n}: record lengths`);
  const time = BigInt(p.header.timestampSeconds) * 1000000n + BigInt(p.header.timestampMicroseconds);
  if (time < lastTime) fail(`frame ${n}: capture time goes backwards`);
  lastTime = time;
  if (port === kDataPort) {
    if (payload.length !== 1206) fail(`frame ${n}: data payload ${payload.length} bytes`);
    const expected = logPackets[data];
    if (!expected) fail(`frame ${n}: more data packets in the pcap than in the log`);
    if (Buffer.compare(Buffer.from(expected.data), payload) !== 0) fail(`frame ${n}: data packet ${data} differs from the log's`);
    if (time !== expected.stamp / 1000n) fail(`frame ${n}: capture time ${time} us, packet stamp ${expected.stamp} ns`);
    ++data;
  } else if (port === kPositionPort) {
    if (payload.length !== 512) fail(`frame ${n}: position payload ${payload.length} bytes`);
    const end = payload.indexOf(0, 206);
    const sentence = payload.subarray(206, end).toString("latin1");
    if (!sentence.startsWith("$GPRMC,") || !nmeaChecksumOk(sentence)) fail(`frame ${n}: bad sentence ${JSON.stringify(sentence)}`);
    if (time % 1000000n !== 0n) fail(`frame ${n}: position packet not on a whole second`);
    if (BigInt(payload.readUInt32LE(198)) !== time % 3600000000n) fail(`frame ${n}: position timestamp`);
    positionTimes.push(time);
    ++positions;
  } else fail(`frame ${n}: unexpected UDP port ${port}`);
}
if (data !== packetsInLog) fail(`${data} data packets in the pcap, ${packetsInLog} in the log`);
const first = logPackets[0].stamp / 1000n, last = logPackets[logPackets.length - 1].stamp / 1000n;
const seconds = last / 1000000n - (first + 999999n) / 1000000n + 1n;  // whole seconds within [first, last]
if (BigInt(positions) !== seconds) fail(`${positions} position packets, expected ${seconds} (one per whole second)`);

console.log(JSON.stringify({ scans: scans.length, points, worst_m: worst, data_packets: data, position_packets: positions }));
