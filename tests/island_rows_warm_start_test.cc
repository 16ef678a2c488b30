// Warm starts by row key (constraints/island_rows.h): exact keys first; a strain row whose
// principal direction was matched to another material axis (docs/math.md §2.6, R3) takes the
// unclaimed value of its element's row with the same bound and limit axis (rows with one row per
// principal stretch: any of them), never another element's or bound's.
#include <gtest/gtest.h>

#include <memory>

#include "constraints/deformable_island_body.h"
#include "constraints/island_rows.h"
#include "constraints/row_key_layouts.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kH = 0.01;
constexpr int kSourceId = 7;

// Emits fixed strain-limit rows with the given (element, axis, principal axis, bound) keys.
class FixedStrainRows final : public ConstraintSource {
 public:
  void Add(int element, int axis, int principal_axis, int bound) {
    keys_.push_back(packer_.Pack(element, axis, principal_axis, bound));
  }
  int AppendIslandRows(const IslandIterate& /*iterate*/,
                       std::vector<ConstraintRow>& rows) override {
    for (const std::uint64_t key : keys_) {
      ConstraintRow& row = rows.emplace_back();
      row.key = key;
      row.C = 0.5;
      row.body = 0;
      row.type = RowType::kStrainLimit;
      row.num_nodes = 1;
      row.nodes[0] = 0;
      row.J[0] = Vec3::UnitX();
    }
    return static_cast<int>(keys_.size());
  }
  double CalcIslandViolationSum(const IslandIterate& /*iterate*/) const override { return 0.0; }
  std::uint64_t Key(int element, int axis, int principal_axis, int bound) const {
    return packer_.Pack(element, axis, principal_axis, bound);
  }

 private:
  RowKeyPacker<4> packer_{kStrainLimitRowKey, kSourceId};
  std::vector<std::uint64_t> keys_;
};

// The multipliers the rows of `source` take from `from` on a one-tet body.
VecX WarmStartRows(FixedStrainRows& source, const KeyedMultipliers& from) {
  DeformableBodySettings settings;
  settings.name = "cube";
  auto mesh = std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 1, 1, 1));
  DeformableBody body(std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body.BeginStep(kH, Vec3::Zero());
  DeformableIslandBody island_body(body);
  std::vector<IslandBody*> bodies{&island_body};
  IslandRows rows;
  rows.Collect(kH, bodies, {&source}, {VecX::Zero(3 * island_body.num_blocks())}, 1.0);
  VecX lambda;
  rows.WarmStart(from, lambda);
  return lambda;
}

KeyedMultipliers Sorted(KeyedMultipliers entries) {
  std::sort(entries.begin(), entries.end());
  return entries;
}

TEST(IslandRowsWarmStartTest, ExactKeysComeFirstAndKeepTheirOwnValues) {
  FixedStrainRows source;
  source.Add(3, 1, 1, 1);
  source.Add(3, 2, 2, 1);
  const VecX lambda = WarmStartRows(
      source, Sorted({{source.Key(3, 1, 1, 1), 0.25}, {source.Key(3, 2, 2, 1), 0.75}}));
  EXPECT_EQ(lambda[0], 0.25);
  EXPECT_EQ(lambda[1], 0.75);
}

TEST(IslandRowsWarmStartTest, ARowWhosePrincipalMatchFlippedTakesItsElementsBoundValue) {
  FixedStrainRows source;
  source.Add(3, 2, 2, 1);  // was matched to axis 0 at the last iterate
  const VecX lambda = WarmStartRows(source, Sorted({{source.Key(3, 0, 0, 1), 0.5}}));
  EXPECT_EQ(lambda[0], 0.5);
}

TEST(IslandRowsWarmStartTest, AHyperbolicRowTakesOnlyTheValueOfItsOwnLimitAxis) {
  FixedStrainRows source;
  source.Add(3, 1, 0, 1);  // limit axis j = 1, its direction now matched to axis 0
  const VecX lambda = WarmStartRows(
      source, Sorted({{source.Key(3, 0, 2, 1), 0.5}, {source.Key(3, 1, 2, 1), 0.25}}));
  EXPECT_EQ(lambda[0], 0.25);
}

TEST(IslandRowsWarmStartTest, NoValueCrossesElementsOrBoundsOrIsTakenTwice) {
  FixedStrainRows source;
  source.Add(3, 2, 2, 1);  // exact: keeps 0.5
  source.Add(3, 1, 1, 1);  // no exact key: takes the unclaimed sibling (3, 0, 0, 1)
  source.Add(3, 0, 1, 1);  // hyperbolic row (j = 0, m = 1): only a j = 0 row is its sibling: 0
  source.Add(4, 1, 1, 1);  // element 4 has no value (element 5's is not its sibling): 0
  source.Add(3, 2, 2, 0);  // lower bound: takes (3, 0, 0, 0), not a max-bound value
  const KeyedMultipliers from = Sorted({{source.Key(3, 2, 2, 1), 0.5},
                                        {source.Key(3, 0, 0, 1), 0.125},
                                        {source.Key(3, 0, 0, 0), 2.0},
                                        {source.Key(5, 1, 1, 1), 4.0}});
  const VecX lambda = WarmStartRows(source, from);
  EXPECT_EQ(lambda[0], 0.5);
  EXPECT_EQ(lambda[1], 0.125);
  EXPECT_EQ(lambda[2], 0.0);
  EXPECT_EQ(lambda[3], 0.0);
  EXPECT_EQ(lambda[4], 2.0);
}

}  // namespace
}  // namespace taut
