#include "common/curb_map_file.hpp"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"

namespace lidarloop {

using nlohmann::json;

void write_curb_map(const std::string& path, const CurbMap& map) {
  const LocalFrame frame(map.origin);
  json features = json::array();
  for (size_t i = 0; i < map.curbs.size(); ++i) {
    json coordinates = json::array();
    for (const auto& p : map.curbs[i]) {
      const Geodetic g = frame.to_geodetic(p);
      coordinates.push_back({g.lon_deg, g.lat_deg});
    }
    json properties = {{"kind", "curb"}, {"id", i}};
    if (i < map.kinds.size()) properties["curb"] = map.kinds[i];
    features.push_back({{"type", "Feature"},
                        {"properties", properties},
                        {"geometry", {{"type", "LineString"}, {"coordinates", coordinates}}}});
  }
  // The origin travels with the map as a foreign member, so a reader recovers the same local frame.
  const json doc = {
      {"type", "FeatureCollection"},
      {"lidarloop", {{"world", map.world}, {"origin", {map.origin.lon_deg, map.origin.lat_deg, map.origin.alt_m}}}},
      {"features", features}};
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write file");
  out << doc.dump(1) << '\n';
  if (!out) throw InputError(path + ": write failed");
}

static double coordinate(const json& v, const std::string& path, const char* what) {
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw InputError(path + ": " + what + " is not a finite number");
  return v.get<double>();
}

static CurbMap curb_map_of(const json& doc, const std::string& path) {
  if (!doc.is_object() || doc.value("type", "") != "FeatureCollection" || !doc.contains("features") ||
      !doc["features"].is_array())
    throw InputError(path + ": not a GeoJSON FeatureCollection");
  const json& meta = doc.value("lidarloop", json::object());
  if (!meta.contains("origin") || !meta["origin"].is_array() || meta["origin"].size() != 3)
    throw InputError(path + ": missing lidarloop.origin [lon, lat, alt] (the local frame's origin)");

  CurbMap map;
  map.origin = {coordinate(meta["origin"][1], path, "origin latitude"),
                coordinate(meta["origin"][0], path, "origin longitude"),
                coordinate(meta["origin"][2], path, "origin altitude")};
  if (std::abs(map.origin.lat_deg) > 85 || std::abs(map.origin.lon_deg) > 180)
    throw InputError(path + ": lidarloop.origin is outside the range a local frame supports");
  if (meta.contains("world") && meta["world"].is_string()) map.world = meta["world"];
  const LocalFrame frame(map.origin);
  for (size_t i = 0; i < doc["features"].size(); ++i) {
    const json& f = doc["features"][i];
    const std::string where = "feature " + std::to_string(i);
    if (!f.is_object() || !f.contains("geometry") || !f["geometry"].is_object() ||
        f["geometry"].value("type", "") != "LineString" || !f["geometry"].contains("coordinates") ||
        !f["geometry"]["coordinates"].is_array())
      throw InputError(path + ": " + where + " is not a LineString feature");
    Polyline2d line;
    for (const json& c : f["geometry"]["coordinates"]) {
      if (!c.is_array() || c.size() < 2) throw InputError(path + ": " + where + " has a bad coordinate");
      const double lon = coordinate(c[0], path, "longitude"), lat = coordinate(c[1], path, "latitude");
      if (std::abs(lat) > 90 || std::abs(lon) > 180)
        throw InputError(path + ": " + where + " has a coordinate outside WGS-84 bounds");
      line.push_back(frame.to_local(lat, lon));
    }
    if (line.size() < 2) throw InputError(path + ": " + where + " has fewer than 2 points");
    map.curbs.push_back(std::move(line));
    const json properties = f.value("properties", json::object());
    if (properties.is_object() && properties.contains("curb") && properties["curb"].is_string())
      map.kinds.resize(map.curbs.size()), map.kinds.back() = properties["curb"].get<std::string>();
  }
  if (!map.kinds.empty()) map.kinds.resize(map.curbs.size());
  return map;
}

CurbMap read_curb_map(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open curb map");
  // Any json::exception is the file's fault, not only a parse_error: a number too large for a double
  // (out_of_range, found by fuzz_hd_map), or a member of the wrong type where value() is asked for one.
  try {
    return curb_map_of(json::parse(in), path);
  } catch (const json::parse_error& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  } catch (const json::exception& e) {
    throw InputError(path + ": not a curb map (" + e.what() + ")");
  }
}

}  // namespace lidarloop
