#!/usr/bin/env python3
"""An external localizer for `lidarloop run --method "exec:python3 localizer.py"`, in Python with the
standard library only: the CAN + GPS Kalman filter of ../cpp/can_gps_localizer.cpp, reading the MCAP
stream on stdin record by record and decoding the ROS 2 CDR messages it needs by hand.
Protocol: docs/external-localizer.md. After every /lidar/points message it prints one JSON line (the
pose at the scan's last firing with its `lost` and protection bounds, or {"scan": N} before the first
fix) and flushes; it logs to stderr, because stdout carries the answers only.

    python3 localizer.py [--verbose]
"""
import json
import math
import struct
import sys
from array import array

PROGRAM = "localizer.py"
VERBOSE = "--verbose" in sys.argv[1:]


def log(message):
    print(f"{PROGRAM}: {message}", file=sys.stderr, flush=True)


def fail(message):
    log(message)
    sys.exit(1)


# ---- MCAP (https://mcap.dev/spec): magic, then records of opcode (uint8), length (uint64), content.
MAGIC = b"\x89MCAP0\r\n"
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
OP_METADATA, OP_DATA_END = 0x0C, 0x0F


class Fields:
    """Reads the little-endian fields of one record's content."""

    def __init__(self, data):
        self.data, self.at = data, 0

    def take(self, fmt):
        values = struct.unpack_from("<" + fmt, self.data, self.at)
        self.at += struct.calcsize("<" + fmt)
        return values if len(values) > 1 else values[0]

    def string(self):
        n = self.take("I")
        self.at += n
        return bytes(self.data[self.at - n:self.at]).decode("utf-8")

    def string_map(self):
        end = self.at + 4 + self.take("I")
        out = {}
        while self.at < end:
            key = self.string()
            out[key] = self.string()
        return out

    def rest(self):
        return self.data[self.at:]


def read_exactly(stream, n, what):
    data = stream.read(n)
    if len(data) != n:
        fail(f"the stream ended inside {what}")
    return data


def mcap_records(stream):
    """Yields (opcode, content) for every record of the data section, the records inside an uncompressed
    Chunk included, then checks the summary, footer and trailing magic. stream.read(n) on a pipe blocks
    until n bytes have come, so each record is handed on the moment it is complete (lockstep)."""
    if read_exactly(stream, len(MAGIC), "the magic") != MAGIC:
        fail("stdin is not an MCAP stream (no magic)")
    in_summary = False
    while True:
        opcode, length = struct.unpack("<BQ", read_exactly(stream, 9, "a record's opcode and length"))
        content = memoryview(read_exactly(stream, length, f"a record (opcode {opcode:#x})"))
        if opcode == OP_FOOTER:
            break
        if opcode == OP_DATA_END:
            in_summary = True  # Schema and Channel again, Statistics, indexes: nothing new for us
        elif in_summary:
            continue
        elif opcode == OP_CHUNK:
            yield from chunk_records(content)
        else:
            yield opcode, content
    if read_exactly(stream, len(MAGIC), "the trailing magic") != MAGIC:
        fail("no trailing magic after the footer")


def chunk_records(content):
    f = Fields(content)
    f.take("QQQI")  # message start and end times, uncompressed size and CRC
    compression = f.string()
    if compression:
        fail(f"a chunk compressed with {compression}: the standard library cannot read it; give a recorded "
             "log with `lidarloop replay LOG --method exec:...`, which streams it uncompressed")
    records = f.rest()[8:]  # after the uint64 length of the records
    at = 0
    while at < len(records):
        opcode, length = struct.unpack_from("<BQ", records, at)
        yield opcode, records[at + 9:at + 9 + length]
        at += 9 + length


# ---- CDR (XCDR1, little endian): a 4-byte encapsulation header, then each primitive aligned to its
# own size, counted from the end of that header.
class Cdr:
    def __init__(self, data):
        if bytes(data[:2]) != b"\x00\x01":
            fail("a message that is not little-endian CDR")
        self.data, self.at = data, 4

    def take(self, fmt):
        """Reads fields by struct codes ("d", "4d", "IBI"), each aligned to its size."""
        values, count = [], ""
        for code in fmt:
            if code.isdigit():
                count += code
                continue
            size = struct.calcsize("<" + code)
            self.at += (-(self.at - 4)) % size
            n = int(count or 1)
            values += struct.unpack_from(f"<{n}{code}", self.data, self.at)
            self.at += n * size
            count = ""
        return tuple(values) if len(values) > 1 else values[0]

    def string(self):
        n = self.take("I")  # the length counts the terminating NUL
        self.at += n
        return bytes(self.data[self.at - n:self.at - 1]).decode("utf-8")

    def header_stamp_ns(self):
        """std_msgs/Header: builtin_interfaces/Time stamp (int32 sec, uint32 nanosec), string frame_id."""
        sec, nanosec = self.take("iI")
        self.string()
        return sec * 1_000_000_000 + nanosec


def vehicle_report(data):
    """lidarloop_msgs/VehicleReport: wheel speeds in m/s (front left, front right, rear left, rear right)
    and the steering wheel angle in rad, positive turning left."""
    c = Cdr(data)
    stamp = c.header_stamp_ns()
    speeds = c.take("4d")
    return stamp, speeds, c.take("d")


def nav_sat_fix(data):
    """sensor_msgs/NavSatFix: status (int8 status, uint16 service), latitude and longitude in degrees,
    altitude in m, float64[9] position_covariance (m^2, east-north-up, row major), uint8 covariance type."""
    c = Cdr(data)
    stamp = c.header_stamp_ns()
    status = c.take("b")
    c.take("H")
    lat, lon, _alt = c.take("3d")
    return {"stamp": stamp, "status": status, "lat": lat, "lon": lon, "covariance": c.take("9d")}


def gnss_heading(data):
    """lidarloop_msgs/GnssHeading: heading in rad (0 = east, counter-clockwise) and its variance in rad^2."""
    c = Cdr(data)
    c.header_stamp_ns()
    return c.take("2d")


def scan_end_ns(data):
    """sensor_msgs/PointCloud2 of /lidar/points: the header stamp (the scan's first firing) plus the largest
    t_ns (uint32 nanoseconds after it, per point): the scan's last firing."""
    c = Cdr(data)
    stamp = c.header_stamp_ns()
    c.take("II")  # height, width
    t_offset = None
    for _ in range(c.take("I")):
        name = c.string()
        offset, _datatype, _count = c.take("IBI")
        if name == "t_ns":
            t_offset = offset
    if t_offset is None:
        fail("/lidar/points has no t_ns field")
    c.take("B")  # is_bigendian
    point_step, _row_step, size = c.take("III")
    if point_step % 4 or t_offset % 4:
        fail("/lidar/points: t_ns is not on a 4-byte boundary")
    words = array("I")
    words.frombytes(c.data[c.at:c.at + size])
    if sys.byteorder != "little":
        words.byteswap()
    times = words[t_offset // 4::point_step // 4]
    return stamp + (max(times) if times else 0)


# ---- The map frame: transverse Mercator about the origin's meridian, scale 1 on it, on WGS-84 (the
# series of Snyder, "Map Projections: A Working Manual", USGS 1987, eqs. 8-9 to 8-10): millimetres
# within the few kilometres of a map, far below a fix's error.
WGS84_A = 6378137.0
WGS84_F = 1 / 298.257223563
E2 = WGS84_F * (2 - WGS84_F)
EP2 = E2 / (1 - E2)


def meridian_distance(phi):
    e4, e6 = E2 * E2, E2 * E2 * E2
    return WGS84_A * ((1 - E2 / 4 - 3 * e4 / 64 - 5 * e6 / 256) * phi
                      - (3 * E2 / 8 + 3 * e4 / 32 + 45 * e6 / 1024) * math.sin(2 * phi)
                      + (15 * e4 / 256 + 45 * e6 / 1024) * math.sin(4 * phi)
                      - (35 * e6 / 3072) * math.sin(6 * phi))


class MapFrame:
    def __init__(self, lat0_deg, lon0_deg):
        self.lon0 = math.radians(lon0_deg)
        self.m0 = meridian_distance(math.radians(lat0_deg))

    def to_local(self, lat_deg, lon_deg):
        phi = math.radians(lat_deg)
        s, c, t = math.sin(phi), math.cos(phi), math.tan(phi)
        n = WGS84_A / math.sqrt(1 - E2 * s * s)
        cc = EP2 * c * c
        a = (math.radians(lon_deg) - self.lon0) * c
        x = n * (a + (1 - t * t + cc) * a ** 3 / 6 + (5 - 18 * t * t + t ** 4 + 72 * cc - 58 * EP2) * a ** 5 / 120)
        y = meridian_distance(phi) - self.m0 + n * t * (
            a * a / 2 + (5 - t * t + 9 * cc + 4 * cc * cc) * a ** 4 / 24
            + (61 - 58 * t * t + t ** 4 + 600 * cc - 330 * EP2) * a ** 6 / 720)
        return x, y


# ---- Small dense matrices as lists of rows.
def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def transpose(a):
    return [list(row) for row in zip(*a)]


def wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


# ---- The filter. See ../cpp/can_gps_localizer.cpp for the model and the sources of its noise figures;
# the values here are the same, under the same names.
NOISE = {
    "gps_white_sigma_m": 0.4,
    "gps_bias_tau_s": 120.0,
    "odometry_scale_sigma": 0.01,
    "side_slip_sigma_rad": 0.01,
    "yaw_rate_sigma_rad_per_s": 0.01,
}
X, Y, YAW, BX, BY = range(5)
# How far it says it can be trusted: the C++ example's Integrity, the same figures under the same names.
INTEGRITY = {
    "probability": 0.9999,
    "lost_after_refused_fixes": 3,
    "found_after_accepted_fixes": 3,
}


def normal_two_sided_quantile(probability):
    """k with P(|N(0, 1)| <= k) = probability: bisection on erfc, which decreases in k."""
    lo, hi = 0.0, 40.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if math.erfc(mid / math.sqrt(2.0)) > 1 - probability:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


# The gate on a fix's squared Mahalanobis distance: chi-square with 2 degrees of freedom, whose
# quantile is closed form, P(d^2 <= g) = 1 - exp(-g / 2).
GATE = -2.0 * math.log(1.0 - INTEGRITY["probability"])
K_SIGMA = normal_two_sided_quantile(INTEGRITY["probability"])


class CanGpsFilter:
    """An extended Kalman filter over the rear axle's (x, y, yaw) in the map frame and the receiver's
    slowly wandering position error (bx, by): the fix is position + R(yaw) antenna + bias + white noise."""

    def __init__(self, meta):
        self.wheelbase = meta("vehicle_lf_m") + meta("vehicle_lr_m")
        self.steering_ratio = meta("vehicle_steering_ratio")
        self.antenna = (meta("gps_antenna_x_m"), meta("gps_antenna_y_m"))
        self.ready, self.t, self.speed, self.steer = False, 0, 0.0, 0.0
        # Lost after a run of fixes the gate refused, until fixes pass again after starting over.
        self.lost, self.start_over, self.refused, self.accepted = False, False, 0, 0
        self.bias_var = 0.0  # the bias's stationary variance per axis, from the first fix
        self.s = [0.0] * 5
        self.P = [[0.0] * 5 for _ in range(5)]

    def lever(self, yaw):
        ax, ay = self.antenna
        return math.cos(yaw) * ax - math.sin(yaw) * ay, math.sin(yaw) * ax + math.cos(yaw) * ay

    def on_can(self, stamp, speeds, steering_wheel_angle):
        self.predict_to(stamp)
        self.speed = 0.5 * (speeds[2] + speeds[3])  # the rear axle's centre
        self.steer = steering_wheel_angle / self.steering_ratio

    def predict_to(self, t):
        if not self.ready or t <= self.t:
            return
        dt = (t - self.t) * 1e-9
        v, s = self.speed, self.s
        yaw_rate = v * math.tan(self.steer) / self.wheelbase
        mid = s[YAW] + 0.5 * yaw_rate * dt
        c, n = math.cos(mid), math.sin(mid)
        s[X] += v * dt * c
        s[Y] += v * dt * n
        s[YAW] = wrap(s[YAW] + yaw_rate * dt)
        phi = math.exp(-dt / NOISE["gps_bias_tau_s"])
        F = [[1.0 if i == j else 0.0 for j in range(5)] for i in range(5)]
        F[X][YAW], F[Y][YAW] = -v * dt * n, v * dt * c
        F[BX][BX] = F[BY][BY] = phi
        s[BX] *= phi
        s[BY] *= phi
        P = matmul(matmul(F, self.P), transpose(F))
        # Odometry's error per second, along and across the car, turned into the map frame.
        along = (NOISE["odometry_scale_sigma"] * v) ** 2 * dt
        across = (NOISE["side_slip_sigma_rad"] * v) ** 2 * dt
        P[X][X] += along * c * c + across * n * n
        P[Y][Y] += along * n * n + across * c * c
        P[X][Y] += (along - across) * c * n
        P[Y][X] += (along - across) * c * n
        P[YAW][YAW] += NOISE["yaw_rate_sigma_rad_per_s"] ** 2 * dt
        bias_growth = self.bias_var * (1 - phi * phi)  # keeps the bias's variance stationary
        P[BX][BX] += bias_growth
        P[BY][BY] += bias_growth
        self.P, self.t = P, t

    def on_gps(self, fix, heading, heading_variance, frame):
        if fix["status"] < 0:
            return  # no fix
        zx, zy = frame.to_local(fix["lat"], fix["lon"])
        reported = max(fix["covariance"][0], fix["covariance"][4])
        white = NOISE["gps_white_sigma_m"] ** 2
        if not self.ready or self.start_over:
            # The receiver's reported variance is its whole error: a bias that wanders over minutes and
            # the fix-to-fix scatter. The fix's bias is unknown, so the pose inherits it.
            self.bias_var = max(reported - white, 0.0)
            lx, ly = self.lever(heading)
            self.s = [zx - lx, zy - ly, heading, 0.0, 0.0]
            P = [[0.0] * 5 for _ in range(5)]
            P[X][X] = P[Y][Y] = reported
            P[BX][BX] = P[BY][BY] = self.bias_var
            P[X][BX] = P[BX][X] = P[Y][BY] = P[BY][Y] = -self.bias_var  # pose = fix - bias
            P[YAW][YAW] = heading_variance
            self.P, self.t, self.ready = P, fix["stamp"], True
            self.start_over, self.refused, self.accepted = False, 0, 0
            return
        self.predict_to(fix["stamp"])
        s = self.s
        lx, ly = self.lever(s[YAW])
        H = [[1, 0, -ly, 1, 0], [0, 1, lx, 0, 1]]
        PHt = matmul(self.P, transpose(H))
        S = matmul(H, PHt)
        S[0][0] += white
        S[1][1] += white
        det = S[0][0] * S[1][1] - S[0][1] * S[1][0]
        Si = [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]
        innovation = [zx - (s[X] + lx + s[BX]), zy - (s[Y] + ly + s[BY])]
        d2 = sum(innovation[i] * Si[i][j] * innovation[j] for i in range(2) for j in range(2))
        if d2 > GATE:  # this fix disagrees: leave it out; a run of them and the GPS has parted for good
            self.accepted = 0
            self.refused += 1
            if self.refused >= INTEGRITY["lost_after_refused_fixes"]:
                self.lost = self.start_over = True
            return
        self.refused = 0
        if self.lost:
            self.accepted += 1
            if self.accepted >= INTEGRITY["found_after_accepted_fixes"]:
                self.lost = False
        K = matmul(PHt, Si)
        for i in range(5):
            s[i] += K[i][0] * innovation[0] + K[i][1] * innovation[1]
        s[YAW] = wrap(s[YAW])
        # Joseph form: stays symmetric and positive over thousands of updates.
        IKH = [[(1.0 if i == j else 0.0) - (K[i][0] * H[0][j] + K[i][1] * H[1][j]) for j in range(5)]
               for i in range(5)]
        KRKt = [[white * (K[i][0] * K[j][0] + K[i][1] * K[j][1]) for j in range(5)] for i in range(5)]
        P = matmul(matmul(IKH, self.P), transpose(IKH))
        self.P = [[P[i][j] + KRKt[i][j] for j in range(5)] for i in range(5)]

    def pose_covariance(self):
        """The (x, y, yaw) block, row major."""
        return [self.P[i][j] for i in (X, Y, YAW) for j in (X, Y, YAW)]

    def protection(self):
        """[lateral_m, longitudinal_m]: K_SIGMA sigma of the position across and along the car."""
        c, n = math.cos(self.s[YAW]), math.sin(self.s[YAW])
        P = self.P

        def bound(ux, uy):
            variance = ux * ux * P[X][X] + 2 * ux * uy * P[X][Y] + uy * uy * P[Y][Y]
            return K_SIGMA * math.sqrt(max(0.0, variance))

        return [bound(-n, c), bound(c, n)]


def main():
    schemas, channels = {}, {}
    frame = kf = pending_fix = None
    scans = 0
    out = sys.stdout
    for opcode, content in mcap_records(sys.stdin.buffer):
        if opcode == OP_CHANNEL:
            f = Fields(content)
            channel_id, _schema_id = f.take("HH")
            channels[channel_id] = f.string()  # the topic
        elif opcode == OP_METADATA:
            f = Fields(content)
            if f.string() != "lidarloop.external":
                continue
            values = f.string_map()

            def meta(key):
                if key not in values:
                    fail(f"metadata lidarloop.external has no {key}")
                return float(values[key])

            frame = MapFrame(meta("map_origin_lat_deg"), meta("map_origin_lon_deg"))
            kf = CanGpsFilter(meta)
            if VERBOSE:
                log(f"world {values.get('world')}, antenna {kf.antenna}, wheelbase {kf.wheelbase} m")
        elif opcode == OP_MESSAGE:
            channel_id = struct.unpack_from("<H", content, 0)[0]
            data = content[2 + 4 + 8 + 8:]  # after channel id, sequence, log time, publish time
            topic = channels.get(channel_id)
            if kf is None and topic is not None:
                fail("a message before the lidarloop.external metadata")
            if topic == "/vehicle/report":
                kf.on_can(*vehicle_report(data))
            elif topic == "/gps/fix":
                pending_fix = nav_sat_fix(data)
            elif topic == "/gps/heading" and pending_fix is not None:
                kf.on_gps(pending_fix, *gnss_heading(data), frame)
                pending_fix = None
            elif topic == "/lidar/points":
                t = scan_end_ns(data)
                kf.predict_to(t)
                answer = {"scan": scans}
                if kf.ready:
                    answer.update(stamp_ns=t, x=kf.s[X], y=kf.s[Y], yaw=kf.s[YAW], covariance=kf.pose_covariance(),
                                  lost=kf.lost, protection=kf.protection())
                out.write(json.dumps(answer) + "\n")
                out.flush()  # a pipe is not a terminal: unflushed, the answer would wait in a buffer
                scans += 1
    if VERBOSE:
        log(f"{scans} scans answered")


if __name__ == "__main__":
    main()
