#pragma once
// Small OpenDRIVE maps written inline for the tests of sim/opendrive_*.
#include <cstdio>
#include <string>

namespace lidarloop::odr_test {

inline std::string num(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// A whole file: header (with a geoReference unless it is empty) and the body's roads and junctions.
inline std::string map_text(const std::string& body, const std::string& geo = "+lat_0=49 +lon_0=8") {
  std::string header = "  <header revMajor=\"1\" revMinor=\"6\" name=\"test\">\n";
  if (!geo.empty()) header += "    <geoReference><![CDATA[" + geo + "]]></geoReference>\n";
  header += "  </header>\n";
  return "<?xml version=\"1.0\"?>\n<OpenDRIVE>\n" + header + body + "</OpenDRIVE>\n";
}

// A road with one planView geometry (`shape`, e.g. "<line/>") and the given <lanes> content.
inline std::string road(const std::string& id, double length, const std::string& shape, const std::string& lanes,
                        const std::string& extra = "", double x = 0, double y = 0, double hdg = 0,
                        const std::string& junction = "-1") {
  return "  <road id=\"" + id + "\" length=\"" + num(length) + "\" junction=\"" + junction + "\">\n" + extra +
         "    <planView>\n      <geometry s=\"0\" x=\"" + num(x) + "\" y=\"" + num(y) + "\" hdg=\"" + num(hdg) +
         "\" length=\"" + num(length) + "\">\n        " + shape + "\n      </geometry>\n    </planView>\n" +
         "    <lanes>\n" + lanes + "    </lanes>\n  </road>\n";
}

inline std::string lane(int id, const std::string& type, double width, const std::string& inner = "") {
  return "          <lane id=\"" + std::to_string(id) + "\" type=\"" + type + "\" level=\"false\">\n" +
         "            <width sOffset=\"0\" a=\"" + num(width) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n" + inner +
         "          </lane>\n";
}

// One lane section with the given left and right lanes (inner first) and a broken centre line.
inline std::string section(const std::string& left, const std::string& right, double s = 0) {
  return "      <laneSection s=\"" + num(s) + "\">\n" +
         (left.empty() ? "" : "        <left>\n" + left + "        </left>\n") +
         "        <center><lane id=\"0\" type=\"none\" level=\"false\">" +
         "<roadMark sOffset=\"0\" type=\"broken\" weight=\"standard\" color=\"white\" "
         "width=\"0.12\"/></lane></center>\n" +
         (right.empty() ? "" : "        <right>\n" + right + "        </right>\n") + "      </laneSection>\n";
}

// A two-lane town street as CARLA draws it: 3.5 m driving lanes, a 0.3 m shoulder with a curb mark on
// its outer edge, a 2 m sidewalk (no height: the world raises it).
inline std::string town_lanes() {
  const std::string curb = "            <roadMark sOffset=\"0\" type=\"curb\" width=\"0.15\"/>\n";
  return section(lane(1, "driving", 3.5) + lane(2, "shoulder", 0.3, curb) + lane(3, "sidewalk", 2.0),
                 lane(-1, "driving", 3.5) + lane(-2, "shoulder", 0.3, curb) + lane(-3, "sidewalk", 2.0));
}

}  // namespace lidarloop::odr_test
