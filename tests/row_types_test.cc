// The row-type table (constraints/row_types.h) and the StepStats counters it names.
#include "constraints/row_types.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "constraints/island_rows.h"
#include "constraints/step_stats.h"

namespace taut {
namespace {

TEST(RowTypesTest, TableIsIndexedByTypeWithDistinctNames) {
  std::set<std::string> names;
  for (int i = 0; i < kNumRowTypes; ++i) {
    EXPECT_EQ(static_cast<int>(kRowTypes[i].type), i);
    EXPECT_TRUE(names.insert(kRowTypes[i].name).second) << kRowTypes[i].name;
    EXPECT_GT(std::string(kRowTypes[i].c_unit).size(), 0u);
  }
  EXPECT_TRUE(GetRowTypeInfo(RowType::kStrainLimit).is_limit);
  EXPECT_TRUE(GetRowTypeInfo(RowType::kEnergyLimit).is_limit);
  EXPECT_FALSE(GetRowTypeInfo(RowType::kContact).is_limit);
  EXPECT_STREQ(GetRowTypeInfo(RowType::kRigidContact).name, "rigid_contact");
}

TEST(RowTypesTest, EveryTypeHasItsOwnStepStatsCounter) {
  StepStats stats;
  for (int i = 0; i < kNumRowTypes; ++i) stats.rows_of(kRowTypes[i].type) = 10 + i;
  EXPECT_EQ(stats.rows_strain, 10);
  EXPECT_EQ(stats.rows_energy, 11);
  EXPECT_EQ(stats.rows_contact, 12);
  EXPECT_EQ(stats.rows_rigid_contact, 13);
  EXPECT_EQ(stats.rows_joint, 14);
  EXPECT_EQ(stats.rows_node_height, 15);
  EXPECT_EQ(stats.rows_total(), 10 * kNumRowTypes + kNumRowTypes * (kNumRowTypes - 1) / 2);
  // Totals over islands add every counter.
  StepStats sum;
  AddIslandStats(stats, sum);
  AddIslandStats(stats, sum);
  for (const RowTypeInfo& info : kRowTypes)
    EXPECT_EQ(sum.rows_of(info.type), 2 * stats.rows_of(info.type)) << info.name;
}

TEST(RowTypesTest, LimitRowsAreTheStrainAndEnergyRows) {
  ConstraintRow row;
  for (const RowTypeInfo& info : kRowTypes) {
    row.type = info.type;
    EXPECT_EQ(IsLimitRow(row),
              info.type == RowType::kStrainLimit || info.type == RowType::kEnergyLimit)
        << info.name;
  }
}

}  // namespace
}  // namespace taut
