#!/usr/bin/env python3
"""Generate the low-poly actor meshes in assets/actors/ (Wavefront OBJ).

Run from the repository root:

    python3 tools/assets/make_actor_meshes.py

Python 3 standard library only; the output is deterministic.

Conventions (the C++ loader relies on them):
  * units metres; frame x forward, y left, z up;
  * origin at the centre of the bounding box in x and y, on the ground:
    z = 0 is where the wheels / feet touch, nothing is below it;
  * only `o`, `g`, `usemtl`, `v x y z` and `f a b c` lines (triangles,
    1-based absolute indices), no `mtllib`, at most 6 decimals;
  * faces wound counter-clockwise seen from outside; every primitive is a
    closed solid (checked here: each directed edge is paired with its
    reverse and the enclosed volume is positive). Primitives may overlap.
"""

import math
import os
import sys

MATERIALS = ("vehicle_paint", "glass", "tyre", "metal", "retro_reflector", "cloth", "skin")

OUT_DIR = os.path.join("assets", "actors")


# ---------------------------------------------------------------------------
# small vector helpers (3-tuples)
# ---------------------------------------------------------------------------

def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def lerp(a, b, t):
    return add(a, scale(sub(b, a), t))


# ---------------------------------------------------------------------------
# mesh container
# ---------------------------------------------------------------------------

class Mesh:
    """Vertices plus faces grouped in named parts, each with one material."""

    def __init__(self, name):
        self.name = name
        self.verts = []
        self.parts = []  # [name, material, [(i, j, k), ...]] with 0-based indices

    def part(self, name, material):
        """Start a new part; following primitives are added to it."""
        assert material in MATERIALS, material
        self.parts.append([name, material, []])

    def solid(self, points, tris):
        """Add one closed primitive (local 0-based triangle indices)."""
        check_closed_solid(points, tris)
        base = len(self.verts)
        self.verts.extend(points)
        self.parts[-1][2].extend((base + a, base + b, base + c) for a, b, c in tris)

    def triangle_count(self):
        return sum(len(p[2]) for p in self.parts)

    def bbox(self):
        lo = tuple(min(v[i] for v in self.verts) for i in range(3))
        hi = tuple(max(v[i] for v in self.verts) for i in range(3))
        return lo, hi

    def recentre_xy(self):
        """Shift in x and y so that the bounding-box centre is the origin."""
        lo, hi = self.bbox()
        dx, dy = -(lo[0] + hi[0]) / 2.0, -(lo[1] + hi[1]) / 2.0
        self.verts = [(x + dx, y + dy, z) for x, y, z in self.verts]

    def write_obj(self, path):
        lines = ["o " + self.name]
        lines += ["v %s %s %s" % (fmt(x), fmt(y), fmt(z)) for x, y, z in self.verts]
        for name, material, faces in self.parts:
            lines.append("g " + name)
            lines.append("usemtl " + material)
            lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
        with open(path, "w", newline="\n") as f:
            f.write("\n".join(lines) + "\n")


def fmt(value):
    """At most 6 decimals, trailing zeros stripped, never '-0'."""
    s = "%.6f" % (round(value, 6) + 0.0)
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("", "-0") else s


def check_closed_solid(points, tris):
    edges = set()
    for a, b, c in tris:
        for e in ((a, b), (b, c), (c, a)):
            assert e not in edges, "edge used twice in the same direction"
            edges.add(e)
    for a, b in edges:
        assert (b, a) in edges, "open edge: primitive is not closed"
    volume = sum(dot(points[a], cross(points[b], points[c])) for a, b, c in tris) / 6.0
    assert volume > 0.0, "primitive is inside out (volume %g)" % volume


# ---------------------------------------------------------------------------
# primitives
# ---------------------------------------------------------------------------

# Corner order of a hexahedron: bottom quad 0..3 counter-clockwise seen from
# the top side, i.e. (-x,-y) (+x,-y) (+x,+y) (-x,+y) for an axis-aligned box,
# then the top quad 4..7 in the same order.
HEXA_QUADS = {
    "bottom": (0, 3, 2, 1),
    "top": (4, 5, 6, 7),
    "right": (0, 1, 5, 4),   # -y side, u runs rear -> front
    "front": (1, 2, 6, 5),   # +x side, u runs right -> left
    "left": (2, 3, 7, 6),    # +y side, u runs front -> rear
    "back": (3, 0, 4, 7),    # -x side, u runs left -> right
}


def hexa(m, corners):
    """Any hexahedron with planar-ish faces, corners in HEXA order."""
    tris = []
    for a, b, c, d in HEXA_QUADS.values():
        tris += [(a, b, c), (a, c, d)]
    m.solid(list(corners), tris)
    return corners


def face(corners, side):
    """The 4 corners of one hexahedron face, counter-clockwise from outside."""
    return [corners[i] for i in HEXA_QUADS[side]]


def box(m, x0, x1, y0, y1, z0, z1):
    assert x0 < x1 and y0 < y1 and z0 < z1
    return hexa(m, [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                    (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)])


def frustum(m, bottom, top, z0, z1):
    """Truncated pyramid between two axis-aligned rectangles (x0, x1, y0, y1)
    at heights z0 < z1 (the rectangles need not be centred on each other)."""
    bx0, bx1, by0, by1 = bottom
    tx0, tx1, ty0, ty1 = top
    return hexa(m, [(bx0, by0, z0), (bx1, by0, z0), (bx1, by1, z0), (bx0, by1, z0),
                    (tx0, ty0, z1), (tx1, ty0, z1), (tx1, ty1, z1), (tx0, ty1, z1)])


def oriented_box(m, p0, p1, half_w0, half_d0, half_w1=None, half_d1=None):
    """Tapered box along the axis p0 -> p1 (axis in the x-z plane): half width
    along y and half depth in the x-z plane, given at each end."""
    half_w1 = half_w0 if half_w1 is None else half_w1
    half_d1 = half_d0 if half_d1 is None else half_d1
    e = unit(sub(p1, p0))
    s = (0.0, 1.0, 0.0)
    f = unit(cross(s, e))  # (f, s, e) is right-handed

    def quad(p, w, d):
        return [add(p, add(scale(f, -d), scale(s, -w))), add(p, add(scale(f, d), scale(s, -w))),
                add(p, add(scale(f, d), scale(s, w))), add(p, add(scale(f, -d), scale(s, w)))]

    return hexa(m, quad(p0, half_w0, half_d0) + quad(p1, half_w1, half_d1))


def panel(m, quad, u0, u1, v0, v1, t_out=0.006, t_in=0.004):
    """Thin slab on a face (window, plate, reflector). quad: 4 corners
    counter-clockwise seen from outside; (u, v) in [0, 1]^2 select the
    sub-quad bilinearly (u along quad[0] -> quad[1], v along quad[0] -> quad[3]).
    The slab sticks out t_out along the outward normal and t_in into the face."""
    def at(u, v):
        return lerp(lerp(quad[0], quad[1], u), lerp(quad[3], quad[2], u), v)

    q = [at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)]
    n = unit(cross(sub(quad[1], quad[0]), sub(quad[3], quad[0])))
    hexa(m, [sub(p, scale(n, t_in)) for p in q] + [add(p, scale(n, t_out)) for p in q])


def _basis(axis, ref):
    """Unit vectors u, v perpendicular to unit axis with u x v = axis."""
    ref = ref or ((1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 0.0, 1.0))
    u = unit(sub(ref, scale(axis, dot(ref, axis))))
    return u, cross(axis, u)


def _circle(centre, u, v, r, n):
    # rounded so that e.g. the lowest point of a wheel lands exactly on z = 0
    return [tuple(round(c, 12) for c in add(centre, add(scale(u, r * math.cos(2 * math.pi * k / n)),
                                                         scale(v, r * math.sin(2 * math.pi * k / n)))))
            for k in range(n)]


def cylinder(m, p0, p1, r0, r1=None, n=16, ref=None):
    """Closed (optionally tapered) cylinder from p0 to p1, radius r0 at p0 and
    r1 at p1, n sides. With n a multiple of 4 and the axis horizontal, one
    vertex lies exactly at the bottom (wheels touch z = 0 exactly)."""
    r1 = r0 if r1 is None else r1
    axis = unit(sub(p1, p0))
    u, v = _basis(axis, ref)
    pts = _circle(p0, u, v, r0, n) + _circle(p1, u, v, r1, n) + [p0, p1]
    c0, c1 = 2 * n, 2 * n + 1
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, j, n + j), (i, n + j, n + i), (c0, j, i), (c1, n + i, n + j)]
    m.solid(pts, tris)


def ring(m, centre, axis, r_out, r_in, width, n=16, ref=None):
    """Closed annular prism (a tyre or rim seen as a flat ring)."""
    axis = unit(axis)
    u, v = _basis(axis, ref)
    p0, p1 = sub(centre, scale(axis, width / 2)), add(centre, scale(axis, width / 2))
    o0, o1 = _circle(p0, u, v, r_out, n), _circle(p1, u, v, r_out, n)
    i0, i1 = _circle(p0, u, v, r_in, n), _circle(p1, u, v, r_in, n)
    pts = o0 + o1 + i0 + i1
    O0, O1, I0, I1 = 0, n, 2 * n, 3 * n
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(O0 + i, O0 + j, O1 + j), (O0 + i, O1 + j, O1 + i)]   # outer wall
        tris += [(I0 + j, I0 + i, I1 + i), (I0 + j, I1 + i, I1 + j)]   # inner wall
        tris += [(O1 + i, O1 + j, I1 + j), (O1 + i, I1 + j, I1 + i)]   # +axis side
        tris += [(O0 + j, O0 + i, I0 + i), (O0 + j, I0 + i, I0 + j)]   # -axis side
    m.solid(pts, tris)


def ellipsoid(m, centre, rx, ry, rz, n_lon=12, n_lat=8):
    """Closed UV ellipsoid (axis-aligned); the poles are exactly at z +- rz."""
    cx, cy, cz = centre
    pts = [(cx, cy, cz + rz), (cx, cy, cz - rz)]
    for i in range(1, n_lat):
        theta = math.pi * i / n_lat
        for k in range(n_lon):
            phi = 2 * math.pi * k / n_lon
            pts.append((cx + rx * math.sin(theta) * math.cos(phi),
                        cy + ry * math.sin(theta) * math.sin(phi),
                        cz + rz * math.cos(theta)))

    def idx(i, k):  # ring i in 1..n_lat-1
        return 2 + (i - 1) * n_lon + k % n_lon

    tris = []
    for k in range(n_lon):
        tris.append((0, idx(1, k), idx(1, k + 1)))
        tris.append((1, idx(n_lat - 1, k + 1), idx(n_lat - 1, k)))
        for i in range(1, n_lat - 1):
            a, b = idx(i, k), idx(i, k + 1)
            c, d = idx(i + 1, k), idx(i + 1, k + 1)
            tris += [(a, c, d), (a, d, b)]
    m.solid(pts, tris)


def clip_polygon(poly, xmin=-1e9, xmax=1e9, zmin=-1e9, zmax=1e9):
    """Clip a convex (x, z) polygon to a rectangle (Sutherland-Hodgman)."""
    def clip(pts, inside, cut):
        out = []
        for i, p in enumerate(pts):
            q = pts[(i + 1) % len(pts)]
            if inside(p):
                out.append(p)
            if inside(p) != inside(q):
                out.append(cut(p, q))
        return out

    def cut_x(x):
        return lambda p, q: (x, p[1] + (q[1] - p[1]) * (x - p[0]) / (q[0] - p[0]))

    def cut_z(z):
        return lambda p, q: (p[0] + (q[0] - p[0]) * (z - p[1]) / (q[1] - p[1]), z)

    poly = clip(poly, lambda p: p[0] >= xmin, cut_x(xmin))
    poly = clip(poly, lambda p: p[0] <= xmax, cut_x(xmax))
    poly = clip(poly, lambda p: p[1] >= zmin, cut_z(zmin))
    poly = clip(poly, lambda p: p[1] <= zmax, cut_z(zmax))
    return poly


def prism_xz(m, poly, y0, y1):
    """Side profile extruded across the vehicle: poly is a convex list of
    (x, z) points, counter-clockwise with x to the right and z up (i.e. as
    seen from the right-hand, -y, side), extruded from y0 to y1."""
    n = len(poly)
    for i in range(n):  # convexity (needed for the fan-triangulated caps)
        (ax, az), (bx, bz), (cx, cz) = poly[i], poly[(i + 1) % n], poly[(i + 2) % n]
        assert (bx - ax) * (cz - bz) - (bz - az) * (cx - bx) > -1e-12, "profile not convex"
    pts = [(x, y0, z) for x, z in poly] + [(x, y1, z) for x, z in poly]
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, n + i, n + j), (i, n + j, j)]
    for i in range(1, n - 1):
        tris += [(0, i, i + 1), (n, n + i + 1, n + i)]
    m.solid(pts, tris)


def two_link(p0, p2, l1, l2, bend):
    """Middle joint (knee / elbow) of a two-segment limb from p0 to p2 with
    segment lengths l1, l2, bending towards the direction `bend`."""
    d = sub(p2, p0)
    dist = norm(d)
    assert dist < l1 + l2, "limb cannot reach"
    e = scale(d, 1.0 / dist)
    a = (l1 * l1 - l2 * l2 + dist * dist) / (2 * dist)
    h = math.sqrt(max(l1 * l1 - a * a, 0.0))
    perp = unit(sub(bend, scale(e, dot(bend, e))))
    return add(add(p0, scale(e, a)), scale(perp, h))


def wheel(m, name, x, y_centre, radius, width, rim_radius=None, n=16):
    """Tyre (cylinder along y touching z = 0) and, if rim_radius is given, a
    metal rim disc standing 5 mm proud of the tyre's outer face."""
    y0, y1 = y_centre - width / 2, y_centre + width / 2
    m.part(name, "tyre")
    cylinder(m, (x, y0, radius), (x, y1, radius), radius, n=n)
    if rim_radius:
        outer = y1 if y_centre > 0 else y0
        side = 1.0 if y_centre > 0 else -1.0
        m.part(name + "_rim", "metal")
        a, b = sorted((outer - side * 0.02, outer + side * 0.005))
        cylinder(m, (x, a, radius), (x, b, radius), rim_radius, n=n)


# ---------------------------------------------------------------------------
# actors
# ---------------------------------------------------------------------------

def make_car():
    """Sedan 4.6 x 1.85 x 1.45 m, wheelbase 2.75 m, ground clearance 0.18 m."""
    m = Mesh("car")
    half_w = 0.925
    front_axle, rear_axle = 1.40, -1.35
    wheel_r, wheel_w = 0.32, 0.22
    wheel_y = 0.90 - wheel_w / 2          # tyre outer face 2.5 cm inside the body side
    arch_half, arch_top = 0.42, 0.70
    core_half_w = wheel_y - wheel_w / 2 - 0.04

    # side profile (x, z) of the lower body: bumpers, bonnet, boot deck
    profile = [(-2.25, 0.18), (2.20, 0.18), (2.30, 0.32), (2.30, 0.66), (2.10, 0.75),
               (0.95, 0.90), (-1.70, 0.93), (-2.25, 0.88), (-2.30, 0.72), (-2.30, 0.30)]

    m.part("body", "vehicle_paint")
    # full width above the wheel arches
    prism_xz(m, clip_polygon(profile, zmin=arch_top), -half_w, half_w)
    # full width below, between / outside the wheel arches
    for x0, x1 in ((-2.5, rear_axle - arch_half), (rear_axle + arch_half, front_axle - arch_half),
                   (front_axle + arch_half, 2.5)):
        prism_xz(m, clip_polygon(profile, xmin=x0, xmax=x1, zmax=arch_top), -half_w, half_w)
    # narrow floor / engine core between the wheels (the wheel wells' inner wall)
    prism_xz(m, clip_polygon(profile, zmax=arch_top), -core_half_w, core_half_w)

    # greenhouse: tapered cabin, roof at 1.45 m; glass panels on its faces
    cabin = frustum(m, (-1.70, 1.00, -0.80, 0.80), (-0.95, 0.25, -0.66, 0.66), 0.88, 1.45)
    m.part("windscreen", "glass")
    panel(m, face(cabin, "front"), 0.05, 0.95, 0.12, 0.93)
    m.part("rear_window", "glass")
    panel(m, face(cabin, "back"), 0.06, 0.94, 0.14, 0.92)
    m.part("side_windows", "glass")
    for side in ("right", "left"):
        # u runs rear -> front on the right side, front -> rear on the left side
        q = face(cabin, side)
        spans = ((0.10, 0.47), (0.52, 0.90)) if side == "right" else ((0.10, 0.48), (0.53, 0.90))
        for u0, u1 in spans:
            panel(m, q, u0, u1, 0.12, 0.90)

    m.part("headlights", "glass")
    for s in (1, -1):
        y0, y1 = sorted((s * 0.55, s * 0.85))
        box(m, 2.298, 2.306, y0, y1, 0.55, 0.64)

    m.part("license_plate", "retro_reflector")
    box(m, -2.306, -2.298, -0.26, 0.26, 0.42, 0.53)
    m.part("rear_reflectors", "retro_reflector")
    for s in (1, -1):
        y0, y1 = sorted((s * 0.62, s * 0.72))
        box(m, -2.306, -2.298, y0, y1, 0.40, 0.44)

    for axle, x in (("f", front_axle), ("r", rear_axle)):
        for s, side in ((1, "l"), (-1, "r")):
            wheel(m, "wheel_" + axle + side, x, s * wheel_y, wheel_r, wheel_w, rim_radius=0.19)
    return m


def make_bus():
    """Coach 12 x 2.55 x 3.3 m, body floor 0.40 m above the road; only the
    wheels touch the ground (front axle 2.7 m behind the front, rear dual
    axle 3.3 m before the rear end)."""
    m = Mesh("bus")
    half_l, half_w = 6.0, 1.275
    front_axle, rear_axle = half_l - 2.7, -half_l + 3.3
    wheel_r = 0.5
    tyre_out = 1.25                        # outer tyre face, |y|
    front_w, dual_w, dual_gap = 0.30, 0.26, 0.03
    arch_half, arch_top = 0.62, 1.05
    bottom = 0.40

    profile = [(-6.0, bottom), (6.0, bottom), (6.0, 1.10), (5.88, 3.0), (5.78, 3.15),
               (-5.92, 3.15), (-6.0, 3.0)]
    m.part("body", "vehicle_paint")
    prism_xz(m, clip_polygon(profile, zmin=arch_top), -half_w, half_w)
    for x0, x1 in ((-7, rear_axle - arch_half), (rear_axle + arch_half, front_axle - arch_half),
                   (front_axle + arch_half, 7)):
        prism_xz(m, clip_polygon(profile, xmin=x0, xmax=x1, zmax=arch_top), -half_w, half_w)
    # wheel-well inner walls (narrower body between the tyres)
    front_core = tyre_out - front_w - 0.05
    rear_core = tyre_out - 2 * dual_w - dual_gap - 0.05
    for xa, hw in ((front_axle, front_core), (rear_axle, rear_core)):
        prism_xz(m, clip_polygon(profile, xmin=xa - arch_half, xmax=xa + arch_half, zmax=arch_top),
                 -hw, hw)
    # rounded-off roof
    frustum(m, (-5.92, 5.78, -half_w, half_w), (-5.80, 5.55, -1.12, 1.12), 3.15, 3.30)

    # glazing: windscreen on the raked front face, side window band 1.3 - 2.7 m
    m.part("windscreen", "glass")
    windscreen = [(6.0, -half_w, 1.10), (6.0, half_w, 1.10), (5.88, half_w, 3.0), (5.88, -half_w, 3.0)]
    panel(m, windscreen, 0.03, 0.97, 0.05, 0.97)

    def side_windows(y_sign, x0, x1, n, z0=1.30, z1=2.70, pillar=0.12):
        step = (x1 - x0 + pillar) / n
        for i in range(n):
            a = x0 + i * step
            b = a + step - pillar
            y0, y1 = sorted((y_sign * (half_w - 0.004), y_sign * (half_w + 0.006)))
            box(m, a, b, y0, y1, z0, z1)

    m.part("side_windows", "glass")
    side_windows(+1, -5.75, 5.70, 8)                     # left (driver) side
    side_windows(-1, -5.75, 3.95, 7)                     # right (door) side
    side_windows(-1, 5.15, 5.70, 1)                      # right side, ahead of the door
    m.part("door", "glass")
    side_windows(-1, 4.05, 5.05, 1, z0=0.55, z1=2.70)    # glazed front door
    m.part("rear_window", "glass")
    box(m, -6.006, -5.997, -1.10, 1.10, 2.20, 2.90)
    m.part("headlights", "glass")
    for s in (1, -1):
        y0, y1 = sorted((s * 0.80, s * 1.15))
        box(m, 5.997, 6.006, y0, y1, 0.70, 0.86)

    m.part("rear_reflectors", "retro_reflector")
    for s in (1, -1):
        y0, y1 = sorted((s * 1.05, s * 1.17))
        box(m, -6.006, -5.997, y0, y1, 0.55, 0.62)
    m.part("license_plate", "retro_reflector")
    box(m, -6.006, -5.997, -0.26, 0.26, 0.60, 0.71)
    m.part("side_reflectors", "retro_reflector")
    for x in (-5.2, -1.0, 1.5, 5.5):
        for s in (1, -1):
            y0, y1 = sorted((s * (half_w - 0.004), s * (half_w + 0.006)))
            box(m, x - 0.04, x + 0.04, y0, y1, 0.52, 0.56)

    for s, side in ((1, "l"), (-1, "r")):
        wheel(m, "wheel_f" + side, front_axle, s * (tyre_out - front_w / 2), wheel_r, front_w,
              rim_radius=0.30)
        wheel(m, "wheel_r" + side + "_outer", rear_axle, s * (tyre_out - dual_w / 2), wheel_r, dual_w,
              rim_radius=0.30)
        wheel(m, "wheel_r" + side + "_inner", rear_axle,
              s * (tyre_out - dual_w - dual_gap - dual_w / 2), wheel_r, dual_w)
    return m


def make_truck():
    """Box truck 8.5 x 2.5 x 3.6 m: cab (2.2 m long, 3.0 m high), cargo box
    0.1 m behind it with its floor at 1.1 m, ladder frame 0.5 m above the road."""
    m = Mesh("truck")
    front, rear = 4.25, -4.25
    cab_rear = front - 2.2
    box_front = cab_rear - 0.10
    cab_hw, box_hw = 1.175, 1.25
    front_axle, rear_axle = 3.05, -1.95
    wheel_r = 0.5
    tyre_out = 1.20
    front_w, dual_w, dual_gap = 0.30, 0.26, 0.03
    frame_z0, frame_z1 = 0.50, 0.78
    floor_z, roof_z = 1.10, 3.60

    # cab
    m.part("cab", "vehicle_paint")
    cab_profile = [(cab_rear, 1.05), (front, 1.05), (front, 1.70), (4.13, 2.85), (4.02, 3.0),
                   (cab_rear, 3.0)]
    prism_xz(m, cab_profile, -cab_hw, cab_hw)
    box(m, 3.62, front, -cab_hw, cab_hw, 0.62, 1.06)            # grille / front panel
    m.part("cab_windscreen", "glass")
    panel(m, [(front, -cab_hw, 1.70), (front, cab_hw, 1.70), (4.13, cab_hw, 2.85),
              (4.13, -cab_hw, 2.85)], 0.04, 0.96, 0.06, 0.94)
    m.part("cab_side_windows", "glass")
    for s in (1, -1):
        y0, y1 = sorted((s * (cab_hw - 0.004), s * (cab_hw + 0.006)))
        box(m, 2.55, 3.95, y0, y1, 1.75, 2.75)
    m.part("headlights", "glass")
    for s in (1, -1):
        y0, y1 = sorted((s * 0.80, s * 1.10))
        box(m, front - 0.004, front + 0.006, y0, y1, 0.72, 0.88)
    m.part("cab_underside", "metal")
    box(m, 3.95, front, -cab_hw, cab_hw, 0.42, 0.62)           # front bumper
    core = tyre_out - front_w - 0.05
    box(m, cab_rear, 3.62, -core, core, 0.55, 1.06)             # engine / cab floor
    for s in (1, -1):
        y0, y1 = sorted((s * core, s * (cab_hw - 0.02)))
        box(m, cab_rear + 0.03, cab_rear + 0.43, y0, y1, 0.50, 1.06)   # entry steps

    # cargo box
    m.part("cargo_box", "vehicle_paint")
    box(m, rear, box_front, -box_hw, box_hw, floor_z, roof_z)

    # ladder frame, box runners and floor cross-members
    m.part("frame", "metal")
    for s in (1, -1):
        y0, y1 = sorted((s * 0.40, s * 0.50))
        box(m, rear + 0.15, 3.95, y0, y1, frame_z0, frame_z1)           # frame rails
        box(m, rear + 0.05, box_front, y0, y1, frame_z1, 0.96)          # box runners
    for x in (3.30, 1.00, -0.50, -3.20, rear + 0.20):
        box(m, x - 0.04, x + 0.04, -0.40, 0.40, 0.60, 0.72)             # frame cross-members
    x = box_front - 0.10
    while x > rear + 0.1:
        if abs(x - rear_axle) > 0.65:
            box(m, x - 0.04, x + 0.04, -1.22, 1.22, 0.96, floor_z)      # floor cross-members
        x -= 0.60
    # fuel tank (right) and battery box (left) between the axles
    cylinder(m, (-0.20, -0.80, 0.80), (0.70, -0.80, 0.80), 0.27)
    box(m, 0.30, 0.90, 0.52, 1.00, 0.60, 0.98)
    # rear underrun protection
    m.part("underrun_bar", "metal")
    box(m, rear + 0.03, rear + 0.15, -1.10, 1.10, 0.45, 0.60)
    for s in (1, -1):
        y0, y1 = sorted((s * 0.40, s * 0.50))
        box(m, rear + 0.05, rear + 0.15, y0, y1, 0.55, floor_z)

    m.part("license_plate", "retro_reflector")
    box(m, rear + 0.02, rear + 0.028, -0.26, 0.26, 0.61, 0.72)
    m.part("rear_reflectors", "retro_reflector")
    for s in (1, -1):
        y0, y1 = sorted((s * 1.05, s * 1.18))
        box(m, rear - 0.006, rear + 0.004, y0, y1, 1.20, 1.28)
    m.part("side_reflectors", "retro_reflector")
    for x in (-3.6, -0.6, 1.5):
        for s in (1, -1):
            y0, y1 = sorted((s * (box_hw - 0.004), s * (box_hw + 0.006)))
            box(m, x - 0.04, x + 0.04, y0, y1, 1.15, 1.20)

    for s, side in ((1, "l"), (-1, "r")):
        wheel(m, "wheel_f" + side, front_axle, s * (tyre_out - front_w / 2), wheel_r, front_w,
              rim_radius=0.30)
        wheel(m, "wheel_r" + side + "_outer", rear_axle, s * (tyre_out - dual_w / 2), wheel_r, dual_w,
              rim_radius=0.30)
        wheel(m, "wheel_r" + side + "_inner", rear_axle,
              s * (tyre_out - dual_w - dual_gap - dual_w / 2), wheel_r, dual_w)
    return m


def limb(m, p0, p1, r0, r1, n=10):
    """Tapered cylinder, lengthened a little at both ends so joints overlap."""
    d = unit(sub(p1, p0))
    cylinder(m, sub(p0, scale(d, 0.3 * r0)), add(p1, scale(d, 0.3 * r1)), r0, r1, n=n)


def down(angle_deg):
    """Unit vector pointing down, swung forward (+x) by angle_deg."""
    a = math.radians(angle_deg)
    return (math.sin(a), 0.0, -math.cos(a))


def make_pedestrian():
    """Adult 1.75 m tall, mid-stride: left leg forward, right leg back, arms
    swinging the opposite way."""
    m = Mesh("pedestrian")
    hip_z, thigh, shin, ankle_z = 0.92, 0.45, 0.43, 0.08
    hip_y = 0.095

    # front (left) leg straight, angle chosen so the ankle ends at ankle_z
    a_front = math.degrees(math.acos((hip_z - ankle_z) / (thigh + shin)))
    # back (right) leg: thigh 10 deg back, knee bent so the ankle ends at ankle_z
    a_thigh_back = -10.0
    a_shin_back = -math.degrees(math.acos((hip_z - ankle_z - thigh * math.cos(math.radians(10.0))) / shin))

    m.part("legs", "cloth")
    ankles = []
    for y, a_thigh, a_shin in ((hip_y, a_front, a_front), (-hip_y, a_thigh_back, a_shin_back)):
        hip = (0.0, y, hip_z)
        knee = add(hip, scale(down(a_thigh), thigh))
        ankle = add(knee, scale(down(a_shin), shin))
        limb(m, hip, knee, 0.075, 0.055)
        limb(m, knee, ankle, 0.052, 0.04)
        ankles.append(ankle)
    m.part("shoes", "cloth")
    for ax, ay, az in ankles:
        box(m, ax - 0.06, ax + 0.20, ay - 0.05, ay + 0.05, 0.0, 0.095)

    m.part("torso", "cloth")
    box(m, -0.10, 0.10, -0.165, 0.165, 0.85, 1.02)                                # pelvis
    frustum(m, (-0.105, 0.105, -0.155, 0.155), (-0.115, 0.115, -0.20, 0.20), 1.00, 1.44)
    frustum(m, (-0.115, 0.115, -0.20, 0.20), (-0.08, 0.08, -0.12, 0.12), 1.44, 1.49)  # shoulders

    m.part("arms", "cloth")
    hands = []
    # right arm (y-) swings forward, left arm (y+) back; forearm always flexed forward
    for y, a_upper, a_fore in ((-0.205, 20.0, 45.0), (0.205, -20.0, -5.0)):
        shoulder = (0.0, y, 1.42)
        elbow = add(shoulder, scale(down(a_upper), 0.29))
        wrist = add(elbow, scale(down(a_fore), 0.26))
        limb(m, shoulder, elbow, 0.048, 0.04)
        limb(m, elbow, wrist, 0.038, 0.03)
        hands.append(add(wrist, scale(down(a_fore), 0.07)))
    m.part("hands", "skin")
    for h in hands:
        ellipsoid(m, h, 0.045, 0.028, 0.075, n_lon=8, n_lat=6)

    m.part("head", "skin")
    cylinder(m, (0.0, 0.0, 1.46), (0.01, 0.0, 1.59), 0.05, 0.048, n=10)          # neck
    head_rz = 0.105
    ellipsoid(m, (0.012, 0.0, 1.75 - head_rz), 0.098, 0.078, head_rz)             # top at 1.75
    return m


def make_cyclist():
    """City bicycle 1.75 m long (wheels r 0.34 m) with a seated rider, hands on
    the handlebar, right pedal forward; top of the head at 1.75 m."""
    m = Mesh("cyclist")
    wheel_r = 0.34
    rear_axle, front_axle = -(0.875 - wheel_r), 0.875 - wheel_r
    Y = (0.0, 1.0, 0.0)
    X = (1.0, 0.0, 0.0)

    # -- bicycle (side-view geometry in (x, z))
    bb = (-0.115, 0.28)                                     # bottom bracket
    seat_cluster = (bb[0] - 0.52 * math.cos(math.radians(73)), bb[1] + 0.52 * math.sin(math.radians(73)))

    def fork(s):  # point on the steering axis (72 deg head angle) through the front axle
        return (front_axle - s * math.cos(math.radians(72)), wheel_r + s * math.sin(math.radians(72)))

    head_bottom, head_top = fork(0.40), fork(0.56)
    bar = (0.35, 1.00)
    saddle = (-0.30, 0.965)

    def p(xz, y=0.0):
        return (xz[0], y, xz[1])

    m.part("tyres", "tyre")
    for ax in (rear_axle, front_axle):
        ring(m, (ax, 0.0, wheel_r), Y, wheel_r, 0.305, 0.04, n=24, ref=X)
    m.part("frame", "metal")
    for ax in (rear_axle, front_axle):
        ring(m, (ax, 0.0, wheel_r), Y, 0.305, 0.28, 0.025, n=24, ref=X)           # rims
        cylinder(m, (ax, -0.05, wheel_r), (ax, 0.05, wheel_r), 0.025, n=8)        # hubs
    tubes = [
        (p(seat_cluster), p(head_top), 0.016),          # top tube
        (p(bb), p(head_bottom), 0.02),                  # down tube
        (p(bb), p(seat_cluster), 0.016),                # seat tube
        (p(head_bottom), p(head_top), 0.022),           # head tube
        (p(seat_cluster), p(saddle), 0.014),            # seat post
        (p(head_top), p(bar), 0.014),                   # stem
    ]
    for s in (1, -1):
        tubes += [
            (p(bb, s * 0.03), (rear_axle, s * 0.06, wheel_r), 0.011),       # chain stays
            (p(seat_cluster, s * 0.02), (rear_axle, s * 0.06, wheel_r), 0.009),  # seat stays
            (p(head_bottom, s * 0.03), (front_axle, s * 0.055, wheel_r), 0.012),  # fork legs
        ]
    for a, b, r in tubes:
        cylinder(m, a, b, r, n=8)
    cylinder(m, (bar[0], -0.30, bar[1]), (bar[0], 0.30, bar[1]), 0.013, n=8)     # handlebar
    cylinder(m, (bb[0], -0.08, bb[1]), (bb[0], -0.072, bb[1]), 0.10, n=16)        # chainring

    crank, crank_angle = 0.17, math.radians(-20.0)       # right (y-) pedal forward, a bit down
    pedals = {}
    for s in (-1, 1):
        c = math.cos(crank_angle) * (-s), math.sin(crank_angle) * (-s)
        ped = (bb[0] + crank * c[0], bb[1] + crank * c[1])
        pedals[s] = ped
        oriented_box(m, p(bb, s * 0.085), p(ped, s * 0.085), 0.008, 0.015)       # crank arm
        box(m, ped[0] - 0.05, ped[0] + 0.05, min(s * 0.09, s * 0.18), max(s * 0.09, s * 0.18),
            ped[1] - 0.012, ped[1] + 0.012)                                      # pedal
    m.part("saddle", "cloth")
    box(m, saddle[0] - 0.14, saddle[0] + 0.11, -0.075, 0.075, saddle[1] - 0.01, saddle[1] + 0.045)

    m.part("reflectors", "retro_reflector")
    t = (0.83 - seat_cluster[1]) / (saddle[1] - seat_cluster[1])
    sp_x = seat_cluster[0] + (saddle[0] - seat_cluster[0]) * t         # seat post x at z = 0.83
    box(m, sp_x - 0.035, sp_x - 0.015, -0.035, 0.035, 0.80, 0.86)               # rear, under saddle
    box(m, bar[0] + 0.02, bar[0] + 0.035, -0.03, 0.03, 0.93, 0.98)              # front, on stem

    # -- rider
    pelvis = (-0.27, 1.02)
    torso_dir = (math.cos(math.radians(58)), math.sin(math.radians(58)))  # leaning forward
    shoulder_c = (pelvis[0] + 0.58 * torso_dir[0], pelvis[1] + 0.58 * torso_dir[1])
    m.part("rider_torso", "cloth")
    oriented_box(m, p((pelvis[0] - 0.03, pelvis[1] - 0.05)), p(pelvis), 0.165, 0.11)       # pelvis
    oriented_box(m, p(pelvis), p(shoulder_c), 0.155, 0.10, 0.19, 0.11)

    m.part("rider_legs", "cloth")
    feet = []
    for s in (-1, 1):
        ped = pedals[s]
        hip = (saddle[0] + 0.02, s * 0.095, saddle[1] + 0.07)
        ankle = (ped[0] - 0.07, s * 0.125, ped[1] + 0.08)
        knee = two_link(hip, ankle, 0.45, 0.44, X)
        limb(m, hip, knee, 0.072, 0.052)
        limb(m, knee, ankle, 0.05, 0.038)
        feet.append((ped, s))
    m.part("rider_shoes", "cloth")
    for ped, s in feet:
        box(m, ped[0] - 0.13, ped[0] + 0.10, min(s * 0.08, s * 0.17), max(s * 0.08, s * 0.17),
            ped[1] + 0.012, ped[1] + 0.10)

    m.part("rider_arms", "cloth")
    hands = []
    for s in (-1, 1):
        shoulder = (shoulder_c[0], s * 0.19, shoulder_c[1] - 0.03)
        wrist = (bar[0] - 0.05, s * 0.245, bar[1] + 0.025)
        elbow = two_link(shoulder, wrist, 0.29, 0.26, (-1.0, 0.0, -1.0))
        limb(m, shoulder, elbow, 0.046, 0.04)
        limb(m, elbow, wrist, 0.038, 0.03)
        hands.append((bar[0], s * 0.245, bar[1] + 0.01))
    m.part("rider_hands", "skin")
    for h in hands:
        ellipsoid(m, h, 0.05, 0.035, 0.04, n_lon=8, n_lat=6)                     # hands on the grips
    m.part("rider_head", "skin")
    head_rz = 0.105
    head_c = (shoulder_c[0] + 0.08, 0.0, 1.75 - head_rz)
    cylinder(m, p(shoulder_c), (head_c[0] - 0.02, 0.0, head_c[2] - 0.06), 0.05, n=10)   # neck
    ellipsoid(m, head_c, 0.1, 0.078, head_rz)
    return m


ACTORS = (make_car, make_bus, make_truck, make_pedestrian, make_cyclist)


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    for make in ACTORS:
        m = make()
        m.recentre_xy()
        lo, hi = m.bbox()
        assert abs(lo[2]) < 1e-6, "%s: lowest point %.6f is not on the ground" % (m.name, lo[2])
        path = os.path.join(OUT_DIR, m.name + ".obj")
        m.write_obj(path)
        print("%-28s %5d triangles  bbox x [%.3f, %.3f] y [%.3f, %.3f] z [%.3f, %.3f]"
              % (path, m.triangle_count(), lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
