#include <gtest/gtest.h>

#include "demos/tools/report/figure_search.h"

namespace taut {
namespace {

// Figures shaped like the scenes' summaries: per-material entries, null for an unlimited body.
TEST(ReportFigureSearchTest, FindsTheLargestFigureOfAnyBody) {
  const nlohmann::json figures = nlohmann::json::parse(R"({
    "materials": {
      "soft": {"max_energy_ratio": null, "deepest_penetration_m": 0.004},
      "limited": {"max_energy_ratio": 1.03, "deepest_penetration_m": 0.011},
      "limited_more": {"max_energy_ratio": 0.98, "penetration_depth_m": 0.002}
    },
    "presses": [{"max_penetration_m": 0.02}, {"max_energy_ratio": "n/a"}],
    "credit": "text"
  })");
  EXPECT_EQ(FindMaxEnergyRatio(figures), 1.03);
  EXPECT_EQ(FindMaxPenetration(figures), 0.02);  // also inside arrays
}

// No such figure (or only nulls) gives NaN, so the report shows a dash.
TEST(ReportFigureSearchTest, MissingFiguresAreNaN) {
  const nlohmann::json figures =
      nlohmann::json::parse(R"({"materials": {"a": {"max_energy_ratio": null}}, "n": 3})");
  EXPECT_TRUE(std::isnan(FindMaxEnergyRatio(figures)));
  EXPECT_TRUE(std::isnan(FindMaxPenetration(figures)));
  EXPECT_TRUE(std::isnan(FindMaxEnergyRatio(nlohmann::json())));
  EXPECT_EQ(MaxOfKnown(std::nan(""), 2.0), 2.0);
  EXPECT_EQ(MaxOfKnown(3.0, std::nan("")), 3.0);
}

}  // namespace
}  // namespace taut
