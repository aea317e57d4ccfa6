// The paper's tables beside ours: the mean and spread over seeds, and the table's rows.
#include <gtest/gtest.h>

#include "scoring/paper_tables.hpp"

namespace lidarloop {
namespace {

Metrics run(const std::string& method, double lateral, double longitudinal, double heading) {
  Metrics m;
  m.method = method;
  m.lateral_rmse_m = lateral, m.longitudinal_rmse_m = longitudinal, m.heading_rmse_deg = heading;
  return m;
}

TEST(PaperTables, SummariseGivesEachMethodsMeanAndExtremesOverSeeds) {
  const auto s =
      summarise_over_seeds({run("icp", 0.1, 1.0, 0.5), run("proposed", 0.02, 0.2, 0.1), run("icp", 0.3, 2.0, 0.7),
                            run("proposed", 0.04, 0.1, 0.3), run("icp", 0.2, 3.0, 0.6)});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].method, "icp");
  EXPECT_EQ(s[0].seeds, 3u);
  EXPECT_NEAR(s[0].lateral_m.mean, 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(s[0].lateral_m.min, 0.1);
  EXPECT_DOUBLE_EQ(s[0].lateral_m.max, 0.3);
  EXPECT_NEAR(s[0].longitudinal_m.mean, 2.0, 1e-12);
  EXPECT_NEAR(s[1].heading_deg.mean, 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(s[1].longitudinal_m.min, 0.1);
}

TEST(PaperTables, TheTablesHoldThePapersFiguresAndTheMarkdownShowsBoth) {
  const auto& dynamic = paper_table(PaperTable::dynamic_campus);
  ASSERT_EQ(dynamic.size(), 7u);
  EXPECT_EQ(dynamic.back().method, "proposed");
  EXPECT_DOUBLE_EQ(dynamic.back().lateral_m, 0.1884);
  EXPECT_FALSE(paper_table(PaperTable::static_campus)[4].heading_deg.has_value());  // intensity: none
  const std::string md =
      paper_comparison_markdown(PaperTable::dynamic_campus, summarise_over_seeds({run("icp", 0.1, 1.0, 0.5)}));
  EXPECT_NE(md.find("| icp | 0.581 | 0.100 | 2.638 | 1.000 | 3.146 | 0.500 |"), std::string::npos) << md;
  EXPECT_EQ(parse_paper_table("static"), PaperTable::static_campus);
  EXPECT_FALSE(parse_paper_table("table2").has_value());
}

}  // namespace
}  // namespace lidarloop
