#include "scoring/paper_tables.hpp"

#include <algorithm>
#include <cstdio>

namespace lidarloop {

const std::vector<PaperRow>& paper_table(PaperTable table) {
  // Transcribed from the paper's Table II and Table III (RMSE; the intensity method has no heading).
  static const std::vector<PaperRow> kStatic = {{"gps", 1.9942, 2.5449, 1.5034},     {"icp", 0.2131, 0.4436, 0.7184},
                                                {"icp-obs", 0.1943, 0.4353, 0.6478}, {"m-icp", 0.1855, 0.4074, 0.5766},
                                                {"intensity", 0.2983, 0.4145, {}},   {"fmt", 0.4101, 0.5905, 0.8929},
                                                {"proposed", 0.1885, 0.3933, 0.5195}};
  static const std::vector<PaperRow> kDynamic = {{"gps", 1.9509, 1.8668, 2.1533},     {"icp", 0.5812, 2.6381, 3.1461},
                                                 {"icp-obs", 0.2210, 0.4990, 0.8338}, {"m-icp", 0.2035, 0.4964, 0.9514},
                                                 {"intensity", 0.3130, 0.5614, {}},   {"fmt", 0.7467, 0.8975, 0.8356},
                                                 {"proposed", 0.1884, 0.4568, 0.5283}};
  return table == PaperTable::static_campus ? kStatic : kDynamic;
}

std::optional<PaperTable> parse_paper_table(const std::string& word) {
  if (word == "static") return PaperTable::static_campus;
  if (word == "dynamic") return PaperTable::dynamic_campus;
  return std::nullopt;
}

namespace {
void add(SeedSpread& s, double v, size_t n) {
  s.mean += (v - s.mean) / double(n);  // running mean
  s.min = n == 1 ? v : std::min(s.min, v);
  s.max = n == 1 ? v : std::max(s.max, v);
}

std::string fixed(double v, const char* format) {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string ours(const SeedSpread& s, size_t seeds) {
  if (seeds < 2) return fixed(s.mean, "%.3f");
  return fixed(s.mean, "%.3f") + " (" + fixed(s.min, "%.3f") + "-" + fixed(s.max, "%.3f") + ")";
}
}  // namespace

std::vector<MethodOverSeeds> summarise_over_seeds(const std::vector<Metrics>& runs, bool against_reference) {
  std::vector<MethodOverSeeds> out;
  for (const Metrics& m : runs) {
    if (against_reference && !m.reference) continue;
    auto it = std::find_if(out.begin(), out.end(), [&](const MethodOverSeeds& o) { return o.method == m.method; });
    if (it == out.end()) it = out.insert(out.end(), MethodOverSeeds{m.method, 0, {}, {}, {}});
    const size_t n = ++it->seeds;
    add(it->lateral_m, against_reference ? m.reference->lateral_rmse_m : m.lateral_rmse_m, n);
    add(it->longitudinal_m, against_reference ? m.reference->longitudinal_rmse_m : m.longitudinal_rmse_m, n);
    add(it->heading_deg, against_reference ? m.reference->heading_rmse_deg : m.heading_rmse_deg, n);
  }
  return out;
}

std::string paper_comparison_markdown(PaperTable table, const std::vector<MethodOverSeeds>& ours_rows) {
  std::string md =
      std::string("| method | lateral m: paper | ours | longitudinal m: paper | ours | heading deg: paper | ours |\n") +
      "|---|---:|---:|---:|---:|---:|---:|\n";
  for (const MethodOverSeeds& o : ours_rows) {
    const auto& rows = paper_table(table);
    const auto p = std::find_if(rows.begin(), rows.end(), [&](const PaperRow& r) { return r.method == o.method; });
    const bool known = p != rows.end();
    md += "| " + o.method + " | " + (known ? fixed(p->lateral_m, "%.3f") : "-") + " | " + ours(o.lateral_m, o.seeds) +
          " | " + (known ? fixed(p->longitudinal_m, "%.3f") : "-") + " | " + ours(o.longitudinal_m, o.seeds) + " | " +
          (known && p->heading_deg ? fixed(*p->heading_deg, "%.3f") : "-") + " | " + ours(o.heading_deg, o.seeds) +
          " |\n";
  }
  return md;
}

}  // namespace lidarloop
