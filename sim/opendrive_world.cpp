#include "sim/opendrive_world.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <sstream>

#include "common/input_error.hpp"
#include "sim/actor_assets.hpp"
#include "sim/import_report.hpp"
#include "sim/opendrive_geometry.hpp"
#include "sim/opendrive_paint.hpp"
#include "sim/region.hpp"
#include "sim/scattered_heights.hpp"
#include "sim/triangle_heights.hpp"

namespace lidarloop {
namespace {

constexpr double kRoadTile = 0.5;                         // m: pavement squares (roughness)
constexpr double kPavedTile = 0.5, kPavedSquare = 1.0;    // m: sidewalks
constexpr double kGroundTile = 2.0, kGroundSquare = 8.0;  // m: the ground beside the roads
constexpr double kRoofTile = 4.0;                         // m: roofs are flat
constexpr double kFoundation = 0.3;                       // m: buildings reach this far into the ground
constexpr double kEdgePiece = 0.5;                        // m: the carriageway's edge is tested in pieces this long
constexpr double kProbe = 0.05;                           // m beside the edge where the raised ground is read
constexpr double kMinWidth = 0.01;                        // m: narrower lanes are placeholders, not strips

// Lane types that are part of the carriageway (ASAM OpenDRIVE 1.8, 11.7.2 e_laneType, and the older
// names 1.4 used).
const std::set<std::string>& pavement_types() {
  static const std::set<std::string> types = {
      "driving",  "parking",       "biking",         "shoulder", "border",  "restricted", "median",   "stop",
      "entry",    "exit",          "onRamp",         "offRamp",  "bus",     "taxi",       "HOV",      "roadWorks",
      "slipLane", "bidirectional", "connectingRamp", "mwyEntry", "mwyExit", "special1",   "special2", "special3"};
  return types;
}
bool is_walk_type(const std::string& t) { return t == "sidewalk" || t == "walking" || t == "curb"; }

// One lane of one lane section, sampled along s: its surface's edges.
struct Strip {
  const OdrRoad* road = nullptr;
  size_t section = 0;
  const OdrLane* lane = nullptr;
  bool raised = false;
  bool outermost = false;     // the last strip on its side of the road
  bool curb_outside = false;  // a curb mark on its outer edge
  std::vector<double> s;
  std::vector<Eigen::Vector3d> inner, outer;

  Polyline2d polygon() const {
    Polyline2d out;
    for (const auto& p : inner) out.push_back(p.head<2>());
    for (auto it = outer.rbegin(); it != outer.rend(); ++it) out.push_back(it->head<2>());
    return out;
  }
};

bool has_own_height(const OdrLane& lane, double threshold) {
  return std::any_of(lane.height.begin(), lane.height.end(), [&](const OdrLaneHeight& h) {
    return std::abs(h.inner) > threshold || std::abs(h.outer) > threshold;
  });
}
bool has_curb_mark(const OdrLane& lane) {
  return std::any_of(lane.marks.begin(), lane.marks.end(), [](const OdrRoadMark& m) { return m.type == "curb"; });
}

struct Builder {
  Builder(const OdrMap& m, const OdrWorldParams& p, const MaterialTable& mt, const std::string& actors,
          OdrBuildReport& r)
      : map(m), params(p), materials(mt), actors_dir(actors), report(r) {}
  const OdrMap& map;
  const OdrWorldParams& params;
  const MaterialTable& materials;
  const std::string& actors_dir;
  OdrBuildReport& report;
  World world;
  std::vector<Strip> strips;
  std::shared_ptr<TriangleHeights> pavement = std::make_shared<TriangleHeights>();
  std::shared_ptr<TriangleHeights> raised = std::make_shared<TriangleHeights>();
  std::shared_ptr<const ScatteredHeights> beside;
  std::function<double(const Eigen::Vector2d&)> surface_at;  // the pavement, else the raised ground

  MaterialId mat(const std::string& name) const { return materials.id(name, map.file); }

  // Every lane of every section as a strip of samples; which are raised.
  void sample_lanes() {
    std::set<std::string> junction_ids;
    for (const auto& road : map.roads) {
      (road.junction == "-1" ? report.roads : report.junction_roads)++;
      if (road.junction != "-1") junction_ids.insert(road.junction);
      report.road_length_m += road.length;
      for (size_t i = 0; i < road.sections.size(); ++i) {
        const OdrLaneSection& sec = road.sections[i];
        const double s0 = sec.s, s1 = std::min(road.section_end(i), road.length);
        if (s1 - s0 < 1e-6) continue;
        std::vector<double> ss;
        const int n = std::max(1, int(std::ceil((s1 - s0) / params.step)));
        for (int k = 0; k <= n; ++k) ss.push_back(s0 + (s1 - s0) * k / n);
        for (const auto* side : {&sec.left, &sec.right}) {
          bool behind_curb = false;
          size_t last = strips.size();
          for (const auto& lane : *side) {
            const bool walk = is_walk_type(lane.type), paved = pavement_types().count(lane.type) > 0;
            const bool curb_here = has_curb_mark(lane);
            if (!walk && !paved) {
              ++report.not_built["lane of type " + lane.type];
              behind_curb = behind_curb || curb_here;
              continue;
            }
            Strip st{&road, i, &lane, false, false, curb_here, ss, {}, {}};
            double extra = 0;
            if (walk) {
              st.raised = true;
              if (lane.height.empty()) extra = params.sidewalk_height, ++report.raised_by_default;
            } else if (has_own_height(lane, params.curb_threshold)) {
              st.raised = true;
            } else if (behind_curb && lane.height.empty()) {
              st.raised = true, extra = params.sidewalk_height;
              ++report.raised_by_curb_mark;
            }
            double widest = 0;
            for (const double s : ss) {
              const OdrLaneEdges e = lane_edges(road, i, lane.id, s);
              widest = std::max(widest, std::abs(e.outer - e.inner));
              st.inner.push_back(lane_surface_point(road, i, lane, s, e.inner) + Eigen::Vector3d(0, 0, extra));
              st.outer.push_back(lane_surface_point(road, i, lane, s, e.outer) + Eigen::Vector3d(0, 0, extra));
            }
            behind_curb = behind_curb || curb_here;
            if (widest < kMinWidth) {
              ++report.not_built["lane of zero width"];
              continue;
            }
            ++report.lanes[lane.type];
            last = strips.size();
            strips.push_back(std::move(st));
          }
          if (last < strips.size()) strips[last].outermost = true;
        }
      }
    }
    report.junctions = int(map.junctions.size());
    if (std::none_of(strips.begin(), strips.end(), [](const Strip& s) { return !s.raised; }))
      throw InputError(map.file + ": no driving lane: the world has no carriageway");
  }

  // The lanes' surfaces as triangles to look heights up in; the ground beside the roads continues
  // from the outermost lanes' outer edges (a curb mark there raises it); junctions' connecting roads
  // are left out of that, so a junction's corners take the level of the sidewalks round them.
  void surfaces() {
    std::vector<Eigen::Vector2d> pts;
    std::vector<double> zs;
    const bool any_outside =
        std::any_of(map.roads.begin(), map.roads.end(), [](const OdrRoad& r) { return r.junction == "-1"; });
    for (const Strip& st : strips) {
      TriangleHeights& index = st.raised ? *raised : *pavement;
      for (size_t k = 1; k < st.s.size(); ++k)
        index.add_quad(st.inner[k - 1], st.outer[k - 1], st.outer[k], st.inner[k]);
      // A road's open end (no predecessor or successor): the ground beyond it stays at its level.
      const bool open_start = !st.road->predecessor && st.section == 0;
      const bool open_end = !st.road->successor && st.section + 1 == st.road->sections.size();
      for (const bool at_start : {true, false}) {
        if (!(at_start ? open_start : open_end)) continue;
        const size_t k = at_start ? 0 : st.s.size() - 1;
        const int n = std::max(1, int(std::ceil((st.outer[k] - st.inner[k]).norm() / params.step)));
        for (int j = 0; j <= n; ++j) {
          const Eigen::Vector3d p = st.inner[k] + (st.outer[k] - st.inner[k]) * (double(j) / n);
          pts.push_back(p.head<2>()), zs.push_back(p.z());
        }
      }
      if (!st.outermost || (any_outside && st.road->junction != "-1")) continue;
      const double lift = st.curb_outside && !st.raised ? params.sidewalk_height : 0.0;
      for (const auto& p : st.outer) pts.push_back(p.head<2>()), zs.push_back(p.z() + lift);
    }
    beside = std::make_shared<const ScatteredHeights>(pts, zs);
    auto pav = pavement, ras = raised;
    auto bes = beside;
    auto terrain = [pav, bes](const Eigen::Vector2d& p) {
      const auto z = pav->near(p);
      return z ? *z : (*bes)(p);
    };
    world.surface = std::make_shared<const RoadSurface>(
        terrain, [](const Eigen::Vector2d&) { return 0.0; }, params.geometry);
    world.raised_level = [ras, bes](const Eigen::Vector2d& p) {
      const auto z = ras->at(p);
      return float(z ? *z : (*bes)(p));
    };
    auto surface = world.surface;
    auto raised_level = world.raised_level;
    surface_at = [pav, surface, raised_level](const Eigen::Vector2d& p) {
      return pav->at(p) ? surface->carriageway(p) : double(raised_level(p));
    };
  }

  region::Paths raised_area, curb_lanes;
  void regions_and_ground() {
    region::Paths road, walk, curb;
    std::map<std::string, region::Paths> junctions;
    Eigen::AlignedBox2d box;
    for (const Strip& st : strips) {
      const Polyline2d poly = st.polygon();
      for (const auto& p : poly) box.extend(p);
      if (poly.size() < 3) continue;
      // Counter-clockwise, whichever side of the road the lane is on: Clipper's non-zero fill would
      // cancel overlapping lanes of opposite turns (a junction's) into holes.
      ClipperLib::Path path = region::to_path(poly);
      if (!ClipperLib::Orientation(path)) ClipperLib::ReversePath(path);
      if (st.raised)
        (st.lane->type == "curb" ? curb : walk).push_back(std::move(path));
      else
        (st.road->junction == "-1" ? road : junctions[st.road->junction]).push_back(std::move(path));
    }
    // A junction's connecting roads overlap and leave islands between their turns that the map means
    // as pavement: each junction's lanes closed and without holes.
    for (const auto& [id, paths] : junctions)
      for (const auto& ring : region::closing(region::unite(paths, {}), params.junction_closing))
        if (ClipperLib::Orientation(ring)) road.push_back(ring);  // outer rings (Clipper: holes run clockwise)
    world.carriageway = region::closing(region::unite(road, {}), params.sliver_radius);
    // Sidewalks closed round the junctions' corners, where the map's sidewalk lanes end.
    curb_lanes = region::subtract(region::unite(curb, {}), world.carriageway);
    raised_area = region::subtract(
        region::subtract(region::closing(region::unite(walk, {}), params.sidewalk_closing), world.carriageway),
        curb_lanes);
    world.sidewalks = region::unite(world.carriageway, region::unite(raised_area, curb_lanes));
    box.min() -= Eigen::Vector2d::Constant(params.geometry.margin);
    box.max() += Eigen::Vector2d::Constant(params.geometry.margin);
    world.bounds = box;

    const RoadSurface& surface = *world.surface;
    const auto pavement_z = [&surface](const Eigen::Vector2d& p) { return float(surface.carriageway(p)); };
    region::mesh_region(world.carriageway, kRoadTile, pavement_z, mat("asphalt"), world.mesh, kRoadTile);
    region::mesh_region(raised_area, kPavedTile, world.raised_level, mat("sidewalk"), world.mesh, kPavedSquare);
    region::mesh_region(curb_lanes, kPavedTile, world.raised_level, mat("curb_concrete"), world.mesh, kPavedSquare);
    const region::Paths off = region::subtract(
        region::rectangle(box.center(), {1, 0}, box.sizes().x() / 2, box.sizes().y() / 2), world.sidewalks);
    region::mesh_region(off, kGroundTile, world.raised_level, mat("grass"), world.mesh, kGroundSquare);
  }

  // A face wherever the ground beside the carriageway's edge is higher or lower; the runs where it
  // is higher by a curb's height are the world's curb lines. Clipper keeps the carriageway on the left
  // of each ring, outer or hole.
  void curbs() {
    const MaterialId concrete = mat("curb_concrete");
    for (const auto& path : world.carriageway) {
      const Polyline2d ring = region::to_polyline(path, true);
      // Points along the ring at most kEdgePiece apart, and per piece the step to the ground outside.
      Polyline2d pts;
      for (size_t i = 1; i < ring.size(); ++i) {
        const int n = std::max(1, int(std::ceil((ring[i] - ring[i - 1]).norm() / kEdgePiece)));
        for (int k = 0; k < n; ++k) pts.push_back(ring[i - 1] + (ring[i] - ring[i - 1]) * (double(k) / n));
      }
      if (pts.size() < 2) continue;
      pts.push_back(pts.front());
      std::vector<double> low(pts.size()), high(pts.size());
      for (size_t k = 0; k < pts.size(); ++k) {
        low[k] = world.surface->carriageway(pts[k]);
        high[k] = world.raised_level(pts[k]);
      }
      std::vector<int> curb(pts.size() - 1, 0);  // per piece: 1 a curb, -1 a drop, 0 flush
      for (size_t k = 0; k + 1 < pts.size(); ++k) {
        const Eigen::Vector2d d = pts[k + 1] - pts[k];
        if (d.norm() < 1e-9) continue;
        const Eigen::Vector2d mid = 0.5 * (pts[k] + pts[k + 1]), out = Eigen::Vector2d(d.y(), -d.x()).normalized();
        const double step = world.raised_level(mid + out * kProbe) - world.surface->carriageway(mid - out * kProbe);
        curb[k] = step > params.curb_threshold && step <= params.max_curb ? 1
                  : std::abs(step) > params.curb_threshold                ? -1
                                                                          : 0;
        if (curb[k] == 0) continue;
        const auto v = static_cast<uint32_t>(world.mesh.vertices.size());
        for (const size_t j : {k, k + 1}) {
          world.mesh.vertices.emplace_back(float(pts[j].x()), float(pts[j].y()), float(std::min(low[j], high[j])));
          world.mesh.vertices.emplace_back(float(pts[j].x()), float(pts[j].y()), float(std::max(low[j], high[j])));
        }
        // Counter-clockwise seen from the carriageway (left of the ring) for a curb, from outside for a drop.
        if (curb[k] > 0) {
          world.mesh.add_triangle(v, v + 1, v + 3, concrete);
          world.mesh.add_triangle(v, v + 3, v + 2, concrete);
        } else {
          world.mesh.add_triangle(v, v + 3, v + 1, concrete);
          world.mesh.add_triangle(v, v + 2, v + 3, concrete);
        }
      }
      // Runs of curb pieces become curb lines; a ring that is curb all round is one closed line.
      const size_t m = curb.size();
      if (std::all_of(curb.begin(), curb.end(), [](int c) { return c == 1; })) {
        add_curb_line(pts);
        continue;
      }
      size_t start = 0;  // a piece that is not curb, so no run is cut where the ring closes
      while (curb[start] == 1) ++start;
      for (size_t k = 0; k < m;) {
        if (curb[(start + k) % m] != 1) {
          ++k;
          continue;
        }
        Polyline2d line{pts[(start + k) % m]};
        for (; k < m && curb[(start + k) % m] == 1; ++k) line.push_back(pts[(start + k) % m + 1]);
        add_curb_line(std::move(line));
      }
    }
  }

  void add_curb_line(Polyline2d line) {
    if (line.size() < 2) return;
    world.curbs.push_back(line);
    world.curb_kinds.push_back("vertical");
    ++report.curb_lines;
    for (size_t i = 1; i < line.size(); ++i) report.curb_length_m += (line[i] - line[i - 1]).norm();
  }

  // Parked cars: parallel stalls along parking lanes and the map's parking spaces, a share of them taken.
  void parking() {
    struct Stall {
      Eigen::Vector2d at;
      double heading;
      bool either_way;  // a bay a car may enter nose first or back in
    };
    std::vector<Stall> stalls;
    for (const Strip& st : strips) {
      if (st.lane->type != "parking") continue;
      const double s0 = st.s.front(), s1 = st.s.back();
      const double mid = 0.5 * (s0 + s1);
      if (lane_width(*st.road, st.section, st.lane->id, mid) < params.stall_min_width) {
        ++report.not_built["parking lane narrower than a stall"];
        continue;
      }
      const int n = int(std::floor((s1 - s0) / params.stall_length));
      const double first = s0 + 0.5 * ((s1 - s0) - n * params.stall_length);
      for (int k = 0; k < n; ++k) {
        const double s = first + (k + 0.5) * params.stall_length;
        const OdrLaneEdges e = lane_edges(*st.road, st.section, st.lane->id, s);
        // Cars face the way the lane's side drives.
        const double heading = reference_pose(*st.road, s).hdg + (st.road->along_s(st.lane->id) ? 0.0 : M_PI);
        stalls.push_back({road_point(*st.road, s, 0.5 * (e.inner + e.outer)).head<2>(), heading, false});
      }
    }
    for (const auto& road : map.roads)
      for (const auto& o : road.objects) {
        if (o.type != "parkingSpace") continue;
        const double heading = reference_pose(road, o.s).hdg + o.hdg + (o.width > o.length ? M_PI / 2 : 0.0);
        stalls.push_back({road_point(road, o.s, o.t).head<2>(), heading, true});
      }
    report.parking_stalls = int(stalls.size());
    if (stalls.empty()) return;
    std::mt19937_64 rng(params.seed);
    std::shuffle(stalls.begin(), stalls.end(), rng);
    const auto taken = size_t(std::llround(std::clamp(params.parking_occupancy, 0.0, 1.0) * double(stalls.size())));
    if (taken == 0) return;
    const TriangleMesh car = load_actor_mesh(actors_dir, ActorType::car, materials);
    for (size_t k = 0; k < taken; ++k) {
      const Stall& st = stalls[k];
      const bool flip = st.either_way && std::uniform_int_distribution<int>(0, 1)(rng) == 1;
      Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
      pose.translate(Eigen::Vector3f(float(st.at.x()), float(st.at.y()), float(surface_at(st.at))));
      pose.rotate(Eigen::AngleAxisf(float(st.heading + (flip ? M_PI : 0.0)), Eigen::Vector3f::UnitZ()));
      world.mesh.append(car, pose);
      ++report.parked_vehicles;
    }
  }

  // Poles and buildings; other objects (crosswalks and parking spaces are built elsewhere) are named.
  void objects() {
    const MaterialId metal = mat("metal"), building = mat("building");
    for (const auto& road : map.roads) {
      for (const auto& o : road.objects) {
        if (o.type == "crosswalk" || o.type == "parkingSpace") continue;
        const Eigen::Vector2d at = road_point(road, o.s, o.t).head<2>();
        const float base = float(surface_at(at) + o.z_offset);
        if (o.type == "pole") {
          const float r = float(o.radius > 0 ? o.radius : params.pole_radius);
          add_frustum(world.mesh, {float(at.x()), float(at.y()), base}, r, r * 0.75f,
                      float(o.height > 0 ? o.height : params.pole_height), 12, metal);
          ++report.poles;
        } else if (o.type == "building") {
          const Polyline2d outline = object_outline(road, o);
          if (outline.size() < 3) {
            ++report.not_built["building without an outline or a size"];
            continue;
          }
          extrude(outline, base - float(kFoundation), base + float(o.height > 0 ? o.height : params.building_height),
                  building);
          ++report.buildings;
        } else {
          ++report.not_built["object " + (o.type.empty() ? std::string("without a type") : o.type)];
        }
      }
      if (road.signals) report.not_built["signal (rules, no geometry)"] += road.signals;
    }
  }

  void extrude(const Polyline2d& ring, float z0, float z1, MaterialId m) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const Eigen::Vector2d a = ring[i], b = ring[(i + 1) % ring.size()];
      const auto v = static_cast<uint32_t>(world.mesh.vertices.size());
      world.mesh.vertices.emplace_back(float(a.x()), float(a.y()), z0);
      world.mesh.vertices.emplace_back(float(b.x()), float(b.y()), z0);
      world.mesh.vertices.emplace_back(float(b.x()), float(b.y()), z1);
      world.mesh.vertices.emplace_back(float(a.x()), float(a.y()), z1);
      world.mesh.add_triangle(v, v + 1, v + 2, m);
      world.mesh.add_triangle(v, v + 2, v + 3, m);
    }
    region::mesh_region(
        region::unite({region::to_path(ring)}, {}), kRoofTile, [z1](const Eigen::Vector2d&) { return z1; }, m,
        world.mesh);
  }
};

}  // namespace

std::string OdrBuildReport::summary() const {
  std::ostringstream o;
  o << "roads: " << roads << " (" << int(std::round(road_length_m)) << " m with junctions' roads), " << junctions
    << " junctions with " << junction_roads << " connecting roads\n";
  o << "lanes:";
  for (const auto& [k, n] : lanes) o << " " << k << " " << n << ",";
  o << " (strips per lane section)\n";
  o << "raised: " << raised_by_default << " sidewalks without height, " << raised_by_curb_mark
    << " lanes behind curb marks (" << curb_marks << " curb marks)\n";
  o << "curbs: " << curb_lines << " lines (" << int(std::round(curb_length_m)) << " m)\n";
  o << "paint:";
  for (const auto& [k, n] : paint) o << " " << k << " " << n << ",";
  o << " crosswalks " << crosswalks << " (" << crosswalk_stripes << " stripes)\n";
  o << "parking: " << parked_vehicles << " parked vehicles in " << parking_stalls << " stalls; poles " << poles
    << ", buildings " << buildings << "\n";
  write_not_built(o, not_built, warnings);
  return o.str();
}

World build_opendrive_world(const OdrMap& map, const OdrWorldParams& params, const MaterialTable& materials,
                            const std::string& actors_dir, OdrBuildReport* report) {
  OdrBuildReport local;
  Builder b(map, params, materials, actors_dir, report ? *report : local);
  b.report = {};
  b.world.name = map.file;
  b.world.origin = map.origin;
  b.sample_lanes();
  b.surfaces();
  b.regions_and_ground();
  b.curbs();
  MarkingPainter painter(params.paint, materials);
  paint_opendrive(map, params, b.surface_at, b.mat("lane_paint"), b.mat("crosswalk_paint"), b.world.mesh, b.report,
                  painter);
  b.world.paint_materials = painter.variants();
  b.parking();
  b.objects();
  for (const auto& w : map.warnings) b.report.warnings.push_back(w);
  if (b.world.curbs.empty())
    b.report.warnings.push_back("the world has no curbs: the curb methods (curb map, curb matching) will find nothing");
  return std::move(b.world);
}

std::shared_ptr<const OpenDriveSource> load_opendrive_source(const std::string& file, const std::string& where,
                                                             const OdrWorldParams& params, const OdrReadOptions& read) {
  auto source = std::make_shared<OpenDriveSource>();
  source->file = file;
  source->where = where;
  source->map = read_opendrive(file, read);
  source->graph = build_opendrive_lane_graph(source->map);
  source->params = params;
  return source;
}

}  // namespace lidarloop
