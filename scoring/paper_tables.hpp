#pragma once
// The paper's Tables II (static campus) and III (dynamic campus), and our runs of the same methods over
// several seeds summarised beside them: for each method the mean RMSE over the seeds and its spread
// (smallest and largest seed), so a reader sees both what the paper measured on real data and how much
// of our figure is the draw of the noise.
#include <optional>
#include <string>
#include <vector>

#include "scoring/scorer.hpp"

namespace lidarloop {

struct PaperRow {
  std::string method;  // our method name (common/localizer_method.hpp)
  double lateral_m, longitudinal_m;
  std::optional<double> heading_deg;  // the paper gives none for the intensity method
};

enum class PaperTable { static_campus, dynamic_campus };  // Table II, Table III
const std::vector<PaperRow>& paper_table(PaperTable table);
std::optional<PaperTable> parse_paper_table(const std::string& word);  // "static" or "dynamic"

struct SeedSpread {
  double mean = 0, min = 0, max = 0;
};
struct MethodOverSeeds {
  std::string method;
  size_t seeds = 0;
  SeedSpread lateral_m, longitudinal_m, heading_deg;
};

// Groups `runs` (one Metrics per method and seed) by method, in first-seen order. `against_reference`:
// the RMSEs against each run's reference (Metrics::reference) instead of the truth, as the paper's own
// were measured; runs without a reference are left out (none: an empty summary).
std::vector<MethodOverSeeds> summarise_over_seeds(const std::vector<Metrics>& runs, bool against_reference = false);

// Markdown: method | lateral paper / ours | longitudinal paper / ours | heading paper / ours, ours as
// "mean (min-max)".
std::string paper_comparison_markdown(PaperTable table, const std::vector<MethodOverSeeds>& ours);

}  // namespace lidarloop
