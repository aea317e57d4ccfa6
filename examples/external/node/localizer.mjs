// An external localizer for `lidarloop run --method "exec:node localizer.mjs"`, in Node.js: the same
// CAN + GPS Kalman filter as ../cpp/can_gps_localizer.cpp, reading the MCAP stream on stdin with
// Foxglove's @mcap/core and decoding ROS 2 CDR with @foxglove/rosmsg2-serialization (the libraries
// Foxglove Studio uses). Protocol: docs/external-localizer.md. After every /lidar/points message it
// prints one JSON line (the pose at the scan's last firing, or {"scan": N} before the first fix).
//
//   node localizer.mjs [--record ESTIMATES.mcap]
//
// --record also writes its estimates as nav_msgs/msg/Odometry on /localizer/odometry into an MCAP
// file at the end, as a ROS 2 localizer recorded with rosbag2 would: `lidarloop score` reads it.
import { open } from "node:fs/promises";

import { parse } from "@foxglove/rosmsg";
import { MessageReader, MessageWriter } from "@foxglove/rosmsg2-serialization";
import { McapStreamReader, McapWriter } from "@mcap/core";

const args = process.argv.slice(2);
const recordPath = args[0] === "--record" ? args[1] : undefined;
if (args.length && !recordPath) {
  console.error("usage: node localizer.mjs [--record ESTIMATES.mcap]");
  process.exit(2);
}

function fail(message) {
  console.error(`localizer.mjs: ${message}`);
  process.exit(1);
}

// ---- The map frame: transverse Mercator about the map origin (scale 1 on its meridian). Within a few
// kilometres of the origin this series is good to millimetres, far below a GPS fix's error.
const WGS84_A = 6378137.0;
const WGS84_F = 1 / 298.257223563;
const E2 = WGS84_F * (2 - WGS84_F);
function localFrame(lat0Deg, lon0Deg) {
  const rad = Math.PI / 180;
  const meridianArc = (phi) => {
    const e4 = E2 * E2, e6 = e4 * E2;
    return WGS84_A * ((1 - E2 / 4 - 3 * e4 / 64 - 5 * e6 / 256) * phi - (3 * E2 / 8 + 3 * e4 / 32 + 45 * e6 / 1024) * Math.sin(2 * phi) +
      (15 * e4 / 256 + 45 * e6 / 1024) * Math.sin(4 * phi) - (35 * e6 / 3072) * Math.sin(6 * phi));
  };
  const m0 = meridianArc(lat0Deg * rad);
  return (latDeg, lonDeg) => {
    const phi = latDeg * rad, dl = (lonDeg - lon0Deg) * rad;
    const s = Math.sin(phi), c = Math.cos(phi), t = Math.tan(phi);
    const nu = WGS84_A / Math.sqrt(1 - E2 * s * s);
    const ep2 = E2 / (1 - E2), eta2 = ep2 * c * c;
    const A = dl * c;
    const x = nu * (A + (1 - t * t + eta2) * A ** 3 / 6 + (5 - 18 * t * t + t ** 4) * A ** 5 / 120);
    const y = meridianArc(phi) - m0 + nu * t * (A * A / 2 + (5 - t * t + 9 * eta2 + 4 * eta2 * eta2) * A ** 4 / 24);
    return [x, y];
  };
}

// ---- The filter: EKF over the rear axle's (x, y, yaw) and the receiver's position bias (bx, by),
// kinematic bicycle on CAN, GPS position = pose + R(yaw) antenna + bias + white noise. The noise figures
// and their sources are the C++ example's, under the same names.
const noise = {
  gpsWhiteSigma: 0.4, // m: the fix-to-fix scatter; the rest of the reported variance is the bias
  gpsBiasTau: 120, // s: the bias's correlation time (minutes: nearly constant over a drive)
  odometryScaleSigma: 0.01, // of the distance driven
  sideSlipSigma: 0.01, // rad
  yawRateSigma: 0.01, // rad/s
};
const [X, Y, YAW, BX, BY] = [0, 1, 2, 3, 4];
const wrap = (a) => Math.atan2(Math.sin(a), Math.cos(a));
const zeros = (r, c) => Array.from({ length: r }, () => new Array(c).fill(0));
const eye = (n) => zeros(n, n).map((row, i) => row.map((_, j) => (i === j ? 1 : 0)));
const matmul = (A, B) => A.map((row) => B[0].map((_, j) => row.reduce((sum, a, k) => sum + a * B[k][j], 0)));
const transpose = (A) => A[0].map((_, j) => A.map((row) => row[j]));
const filter = { ready: false, t: 0n, s: [0, 0, 0, 0, 0], P: eye(5), biasVar: 0, speed: 0, steer: 0 };
let vehicle, toLocal;

function predictTo(t) {
  if (!filter.ready || t <= filter.t) return;
  const dt = Number(t - filter.t) * 1e-9;
  const { s, speed: v } = filter;
  const yawRate = (v * Math.tan(filter.steer)) / vehicle.wheelbase;
  const mid = s[YAW] + 0.5 * yawRate * dt;
  const c = Math.cos(mid), n = Math.sin(mid);
  const phi = Math.exp(-dt / noise.gpsBiasTau);
  s[X] += v * dt * c;
  s[Y] += v * dt * n;
  s[YAW] = wrap(s[YAW] + yawRate * dt);
  s[BX] *= phi;
  s[BY] *= phi;
  const F = eye(5);
  F[X][YAW] = -v * dt * n;
  F[Y][YAW] = v * dt * c;
  F[BX][BX] = F[BY][BY] = phi;
  const P = matmul(matmul(F, filter.P), transpose(F));
  const along = (noise.odometryScaleSigma * v) ** 2 * dt, across = (noise.sideSlipSigma * v) ** 2 * dt;
  P[X][X] += along * c * c + across * n * n;
  P[Y][Y] += along * n * n + across * c * c;
  P[X][Y] += (along - across) * c * n;
  P[Y][X] += (along - across) * c * n;
  P[YAW][YAW] += noise.yawRateSigma ** 2 * dt;
  P[BX][BX] += filter.biasVar * (1 - phi * phi);
  P[BY][BY] += filter.biasVar * (1 - phi * phi);
  filter.P = P;
  filter.t = t;
}

function onGps(fix, heading) {
  if (fix.status.status < 0) return;
  const [ax, ay] = toLocal(fix.latitude, fix.longitude);
  const reported = Math.max(fix.position_covariance[0], fix.position_covariance[4]);
  const white = noise.gpsWhiteSigma ** 2;
  const t = stampNs(fix.header.stamp);
  const lever = (yaw) => [Math.cos(yaw) * vehicle.antenna[0] - Math.sin(yaw) * vehicle.antenna[1],
                          Math.sin(yaw) * vehicle.antenna[0] + Math.cos(yaw) * vehicle.antenna[1]];
  if (!filter.ready) {
    // The first fix's bias is unknown: the pose inherits it (pose = fix - lever - bias).
    const b = Math.max(reported - white, 0);
    const [lx, ly] = lever(heading.heading);
    const P = zeros(5, 5);
    P[X][X] = P[Y][Y] = reported;
    P[BX][BX] = P[BY][BY] = b;
    P[X][BX] = P[BX][X] = P[Y][BY] = P[BY][Y] = -b;
    P[YAW][YAW] = heading.heading_variance;
    Object.assign(filter, { ready: true, t, s: [ax - lx, ay - ly, heading.heading, 0, 0], P, biasVar: b });
    return;
  }
  predictTo(t);
  const s = filter.s;
  const [lx, ly] = lever(s[YAW]);
  const H = [[1, 0, -ly, 1, 0], [0, 1, lx, 0, 1]];
  const PHt = matmul(filter.P, transpose(H));
  const S = matmul(H, PHt);
  S[0][0] += white;
  S[1][1] += white;
  const det = S[0][0] * S[1][1] - S[0][1] * S[1][0];
  const K = matmul(PHt, [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]);
  const v = [ax - (s[X] + lx + s[BX]), ay - (s[Y] + ly + s[BY])];
  for (let i = 0; i < 5; i++) s[i] += K[i][0] * v[0] + K[i][1] * v[1];
  s[YAW] = wrap(s[YAW]);
  // Joseph form: stays symmetric and positive over thousands of updates.
  const IKH = eye(5).map((row, i) => row.map((e, j) => e - (K[i][0] * H[0][j] + K[i][1] * H[1][j])));
  const P = matmul(matmul(IKH, filter.P), transpose(IKH));
  filter.P = P.map((row, i) => row.map((p, j) => p + white * (K[i][0] * K[j][0] + K[i][1] * K[j][1])));
}

// The (x, y, yaw) block, row major.
const poseCovariance = () => [X, Y, YAW].flatMap((i) => [X, Y, YAW].map((j) => filter.P[i][j]));

// ---- The stream.
const stampNs = (s) => BigInt(s.sec) * 1000000000n + BigInt(s.nanosec);

function scanEndNs(cloud) {
  const field = cloud.fields.find((f) => f.name === "t_ns");
  if (!field) fail("/lidar/points has no t_ns field");
  const view = new DataView(cloud.data.buffer, cloud.data.byteOffset, cloud.data.byteLength);
  let last = 0;
  for (let at = field.offset; at < cloud.data.byteLength; at += cloud.point_step) last = Math.max(last, view.getUint32(at, true));
  return stampNs(cloud.header.stamp) + BigInt(last);
}

const schemas = new Map(), channels = new Map(), decoders = new Map();
const estimates = [];
let scans = 0, pendingFix;

function decode(channelId, data) {
  let decoder = decoders.get(channelId);
  if (!decoder) {
    const schema = schemas.get(channels.get(channelId).schemaId);
    decoder = new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true }));
    decoders.set(channelId, decoder);
  }
  return decoder.readMessage(data);
}

function onRecord(record) {
  switch (record.type) {
    case "Schema": schemas.set(record.id, record); break;
    case "Channel": channels.set(record.id, record); break;
    case "Metadata": {
      if (record.name !== "lidarloop.external") break;
      const m = (key) => {
        if (!record.metadata.has(key)) fail(`metadata lidarloop.external has no ${key}`);
        return Number(record.metadata.get(key));
      };
      vehicle = { wheelbase: m("vehicle_lf_m") + m("vehicle_lr_m"), steeringRatio: m("vehicle_steering_ratio"),
                  antenna: [m("gps_antenna_x_m"), m("gps_antenna_y_m")] };
      toLocal = localFrame(m("map_origin_lat_deg"), m("map_origin_lon_deg"));
      break;
    }
    case "Message": {
      const topic = channels.get(record.channelId).topic;
      if (topic === "/vehicle/report") {
        const r = decode(record.channelId, record.data);
        predictTo(stampNs(r.header.stamp));
        filter.speed = 0.5 * (r.wheel_speeds[2] + r.wheel_speeds[3]);
        filter.steer = r.steering_wheel_angle / vehicle.steeringRatio;
      } else if (topic === "/gps/fix") {
        pendingFix = decode(record.channelId, record.data);
      } else if (topic === "/gps/heading" && pendingFix) {
        onGps(pendingFix, decode(record.channelId, record.data));
        pendingFix = undefined;
      } else if (topic === "/lidar/points") {
        const t = scanEndNs(decode(record.channelId, record.data));
        predictTo(t);
        const answer = { scan: scans++ };
        if (filter.ready) {
          const [x, y, yaw] = filter.s, covariance = poseCovariance();
          Object.assign(answer, { stamp_ns: Number(t), x, y, yaw, covariance });
          estimates.push({ t, x, y, yaw, P: covariance });
        }
        process.stdout.write(JSON.stringify(answer) + "\n"); // a pipe: written before this returns
      }
      break;
    }
    default: break;
  }
}

const reader = new McapStreamReader({ validateCrcs: true });
process.stdin.on("data", (chunk) => {
  try {
    reader.append(chunk);
    for (let record; (record = reader.nextRecord()); ) onRecord(record);
  } catch (error) {
    fail(error.message);
  }
});
process.stdin.on("end", async () => {
  if (!reader.done()) fail("the stream ended before its footer");
  if (recordPath) await writeEstimates(recordPath);
});

// ---- --record: the estimates as a rosbag2-style MCAP (ROS 2 profile, CDR).
const ODOMETRY = `std_msgs/Header header
string child_frame_id
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
================================================================================
MSG: geometry_msgs/PoseWithCovariance
geometry_msgs/Pose pose
float64[36] covariance
================================================================================
MSG: geometry_msgs/Pose
geometry_msgs/Point position
geometry_msgs/Quaternion orientation
================================================================================
MSG: geometry_msgs/Point
float64 x
float64 y
float64 z
================================================================================
MSG: geometry_msgs/Quaternion
float64 x 0
float64 y 0
float64 z 0
float64 w 1
================================================================================
MSG: geometry_msgs/TwistWithCovariance
geometry_msgs/Twist twist
float64[36] covariance
================================================================================
MSG: geometry_msgs/Twist
geometry_msgs/Vector3 linear
geometry_msgs/Vector3 angular
================================================================================
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z
`;

async function writeEstimates(path) {
  const file = await open(path, "w");
  let position = 0n;
  const writable = {
    position: () => position,
    write: async (buffer) => { await file.write(buffer); position += BigInt(buffer.byteLength); },
  };
  const writer = new McapWriter({ writable, useStatistics: true, useChunks: true, useSummaryOffsets: true });
  await writer.start({ profile: "ros2", library: "lidarloop example localizer.mjs" });
  const schemaId = await writer.registerSchema({ name: "nav_msgs/msg/Odometry", encoding: "ros2msg", data: new TextEncoder().encode(ODOMETRY) });
  const channelId = await writer.registerChannel({ schemaId, topic: "/localizer/odometry", messageEncoding: "cdr", metadata: new Map() });
  const odometry = new MessageWriter(parse(ODOMETRY, { ros2: true }));
  for (const [i, e] of estimates.entries()) {
    const cov = new Array(36).fill(0);
    const index = [0, 1, 5]; // x, y, yaw in the 6x6 (x y z roll pitch yaw)
    for (let r = 0; r < 3; r++) for (let c = 0; c < 3; c++) cov[6 * index[r] + index[c]] = e.P[3 * r + c];
    const message = {
      header: { stamp: { sec: Number(e.t / 1000000000n), nanosec: Number(e.t % 1000000000n) }, frame_id: "map" },
      child_frame_id: "base_link",
      pose: { pose: { position: { x: e.x, y: e.y, z: 0 }, orientation: { x: 0, y: 0, z: Math.sin(e.yaw / 2), w: Math.cos(e.yaw / 2) } }, covariance: cov },
      twist: { twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }, covariance: new Array(36).fill(0) },
    };
    await writer.addMessage({ channelId, sequence: i, logTime: e.t, publishTime: e.t, data: odometry.writeMessage(message) });
  }
  await writer.end();
  await file.close();
}
