// The node-height row (constraints/node_height_source.h): C_i = z_i - z_min >= 0 on every free
// node, its value and Jacobian against finite differences, a soft body held by it alone, its own
// StepStats counter, and the InputErrors of DeformableWorld::SetNodeHeightLimit.
#include "constraints/node_height_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

// A soft 0.1 m tet cube "height cube" of 2 x 2 x 2 cells (27 nodes) with its lowest corner at
// `corner`, in no world.
std::unique_ptr<DeformableBody> MakeHeightLimitedCube(const Vec3& corner) {
  DeformableBodySettings settings;
  settings.name = "height cube";
  settings.material = {5e4, 0.3, 500.0};
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 2, 2, 2, corner));
  return std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
}

// The rows of `source` at x, by node (the key's only field).
std::map<int, ConstraintRow> NodeHeightRowsByNode(NodeHeightSource& source, const VecX& x) {
  std::vector<ConstraintRow> rows;
  source.AppendRows(x, 0, rows);
  std::map<int, ConstraintRow> by_node;
  for (const ConstraintRow& row : rows) by_node[row.nodes[0]] = row;
  return by_node;
}

// Lowest node height of a body [m].
double LowestNodeHeight(const DeformableBody& body) {
  double z = std::numeric_limits<double>::infinity();
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.node_position(i).z());
  return z;
}

// A soft 0.2 m tet cube "dropped cube" (2 x 2 x 2 cells) whose bottom starts 0.1 m above z = 0,
// in a world with gravity and no ground or other object.
struct NodeHeightDropScene {
  BulletWorldHolder holder;
  DeformableBody* cube = nullptr;

  NodeHeightDropScene() {
    holder.world.setGravity(btVector3(0, 0, -9.81));
    DeformableBodySettings settings;
    settings.name = "dropped cube";
    settings.material = {5e4, 0.3, 500.0};
    settings.mass_damping = 0.5;
    cube = holder.world.AddTetBody(
        MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, 0.1)), settings);
  }
  // One 1/240 s substep per call.
  void Step() { holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0); }
};

TEST(NodeHeightSourceTest, ValueAndJacobianMatchFiniteDifferences) {
  auto body = MakeHeightLimitedCube(Vec3(0.0, 0.0, 0.0));
  body->FixNodes({0});  // a fixed node: no row
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  VecX x = body->x();
  for (Eigen::Index k = 0; k < x.size(); ++k) x[k] += jitter(rng);
  const double z_min = 0.02;
  // A margin above every height: each free node has its row at x and at every perturbation.
  NodeHeightSource source(*body, z_min, 10.0, 3);
  const std::map<int, ConstraintRow> rows = NodeHeightRowsByNode(source, x);
  ASSERT_EQ(static_cast<int>(rows.size()), body->num_nodes() - 1);
  EXPECT_EQ(rows.count(0), 0u);
  // C(x) over the free nodes in node order, and J assembled from the rows.
  const auto values = [&](const VecX& y) {
    const std::map<int, ConstraintRow> at = NodeHeightRowsByNode(source, y);
    VecX c(static_cast<Eigen::Index>(at.size()));
    int r = 0;
    for (const auto& [node, row] : at) c[r++] = row.C;
    return c;
  };
  MatX J = MatX::Zero(static_cast<Eigen::Index>(rows.size()), x.size());
  int r = 0;
  for (const auto& [node, row] : rows) {
    EXPECT_EQ(row.type, RowType::kNodeHeight);
    EXPECT_FALSE(row.bilateral);
    EXPECT_EQ(row.friction_of, 0);
    EXPECT_EQ(row.body2, -1);
    ASSERT_EQ(row.num_nodes, 1);
    EXPECT_NEAR(row.C, x[3 * node + 2] - z_min, 1e-15) << "node " << node;
    EXPECT_EQ(RowKeySource(row.key), 3);
    EXPECT_EQ(RowKeyPayload(row.key), static_cast<std::uint64_t>(node));
    J.block<1, 3>(r++, 3 * node) = row.J[0].transpose();
  }
  const MatX fd = testing::CentralDifference(values, x, 1e-6);
  EXPECT_LT((J - fd).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(NodeHeightSourceTest, RowsOnlyForFreeNodesWithinTheMarginAndViolationsOfFreeNodes) {
  // Node layers at z = -0.05, 0, 0.05; floor z_min = -0.01, margin 0.02: the bottom layer is
  // violated by 0.04 m, the middle one is above the floor but inside the margin (C = 0.01 m), the
  // top one is beyond the margin (C = 0.06 m).
  auto body = MakeHeightLimitedCube(Vec3(0.0, 0.0, -0.05));
  body->FixNodes({BoxNodeIndex(1, 1, 0, 2, 2)});  // a fixed bottom node: no row, no violation
  NodeHeightSource source(*body, -0.01, 0.02, 0);
  const std::map<int, ConstraintRow> rows = NodeHeightRowsByNode(source, body->x());
  EXPECT_EQ(rows.size(), 8u + 9u);
  EXPECT_EQ(rows.count(BoxNodeIndex(1, 1, 0, 2, 2)), 0u);
  for (const auto& [node, row] : rows) EXPECT_LT(body->node_position(node).z(), 0.01);
  EXPECT_NEAR(source.CalcMaxViolation(body->x()), 0.04, 1e-12);
  EXPECT_NEAR(source.CalcViolationSum(body->x()), 8 * 0.04, 1e-12);
  // Raised above the floor by more than the margin: no rows and no violation.
  VecX raised = body->x();
  for (int i = 0; i < body->num_nodes(); ++i) raised[3 * i + 2] += 0.1;
  std::vector<ConstraintRow> none;
  EXPECT_EQ(source.AppendRows(raised, 0, none), 0);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(source.CalcMaxViolation(raised), 0.0);
  EXPECT_EQ(source.CalcViolationSum(raised), 0.0);
}

TEST(NodeHeightSourceTest, SoftCubeRestsOnTheHeightLimitWithNoGroundAndFallsWithout) {
  const double z_min = 0.0;
  NodeHeightDropScene limited, free_fall;
  limited.holder.world.SetNodeHeightLimit(limited.cube, z_min);
  const double tolerance = limited.holder.world.solver_settings().contact_tolerance;
  double deepest = std::numeric_limits<double>::infinity();
  for (int step = 0; step < 360; ++step) {  // 1.5 s: a 0.14 s fall, then more than 1 s at rest
    limited.Step();
    free_fall.Step();
    deepest = std::min(deepest, LowestNodeHeight(*limited.cube));
  }
  const DeformableBody& cube = *limited.cube;
  const double rms_speed = cube.v().norm() / std::sqrt(cube.num_nodes());
  std::printf(
      "node height limit z_min = %.1f: deepest node %.3e m over the run, lowest node %.3e m and "
      "rms speed %.2e m/s at 1.5 s; without it the lowest node is at %.3f m\n",
      z_min, deepest - z_min, LowestNodeHeight(cube) - z_min, rms_speed,
      LowestNodeHeight(*free_fall.cube));
  for (int i = 0; i < cube.num_nodes(); ++i)
    EXPECT_GT(cube.node_position(i).z(), z_min - tolerance) << "node " << i;
  EXPECT_GT(deepest, z_min - tolerance);            // held at the 1.4 m/s impact too
  EXPECT_LT(LowestNodeHeight(cube), z_min + 1e-3);  // it did land on the limit
  EXPECT_LT(rms_speed, 0.05);                       // and is at rest
  EXPECT_TRUE(limited.holder.world.last_step_stats().converged);
  EXPECT_LT(LowestNodeHeight(*free_fall.cube), z_min - 1.0);  // free fall: 11 m in 1.5 s
}

TEST(NodeHeightSourceTest, StepStatsCountTheRowsUnderTheirOwnType) {
  const RowTypeInfo& info = GetRowTypeInfo(RowType::kNodeHeight);
  EXPECT_STREQ(info.name, "node_height");
  EXPECT_EQ(std::string(info.c_unit).rfind("m ", 0), 0u) << info.c_unit;
  EXPECT_FALSE(info.is_limit);  // a distance row, scaled like contacts in the violation figures

  NodeHeightDropScene scene;
  scene.holder.world.SetNodeHeightLimit(scene.cube, 0.0);
  scene.holder.world.SetNodeHeightLimit(scene.cube, 0.0);  // replaces the first: rows not doubled
  for (int step = 0; step < 240; ++step) scene.Step();
  // At rest the 3 x 3 bottom nodes are on the floor, the next layer 0.1 m above it.
  const StepStats& stats = scene.holder.world.last_step_stats();
  EXPECT_EQ(stats.rows_node_height, 9);
  EXPECT_EQ(stats.rows_of(RowType::kNodeHeight), 9);
  EXPECT_EQ(stats.rows_total(), 9);
  EXPECT_EQ(stats.rows_contact, 0);
  EXPECT_EQ(stats.rows_joint, 0);
  EXPECT_EQ(stats.islands, 1);
  EXPECT_EQ(scene.holder.world.last_call_stats().rows_node_height, 9);
  // ClearLimits removes the source: no rows, and the cube falls.
  scene.holder.world.ClearLimits(scene.cube);
  for (int step = 0; step < 24; ++step) scene.Step();
  EXPECT_EQ(scene.holder.world.last_step_stats().rows_node_height, 0);
  EXPECT_LT(LowestNodeHeight(*scene.cube), -0.01);
}

// Expects fn() to throw InputError whose message contains every one of parts.
template <typename Fn>
void ExpectNodeHeightInputError(Fn&& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no InputError; expected one mentioning '" << parts.front() << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& part : parts)
      EXPECT_NE(what.find(part), std::string::npos) << what << "\n  expected: " << part;
  }
}

TEST(NodeHeightSourceTest, BadInputThrowsInputErrorSayingWhatAndWhere) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  NodeHeightDropScene scene;
  DeformableWorld& world = scene.holder.world;
  for (double z_min : {kNan, kInf, -kInf})
    ExpectNodeHeightInputError([&] { world.SetNodeHeightLimit(scene.cube, z_min); },
                               {"body 'dropped cube'", "node height limit", "z_min", "finite"});
  ExpectNodeHeightInputError([&] { world.SetNodeHeightLimit(nullptr, 0.0); },
                             {"not in this world"});
  auto stray = MakeHeightLimitedCube(Vec3::Zero());
  ExpectNodeHeightInputError([&] { world.SetNodeHeightLimit(stray.get(), 0.0); },
                             {"not in this world"});
  for (double margin : {0.0, -0.01, kNan, kInf})
    ExpectNodeHeightInputError([&] { NodeHeightSource rejected(*stray, 0.0, margin, 0); },
                               {"body 'height cube'", "node height limit", "activation margin"});
  ExpectNodeHeightInputError([&] { NodeHeightSource rejected(*stray, 0.0, 0.01, 1 << 16); },
                             {"node height", "source id"});
  // A rejected limit leaves the earlier one in place: the cube still rests on z = 0.
  world.SetNodeHeightLimit(scene.cube, 0.0);
  EXPECT_THROW(world.SetNodeHeightLimit(scene.cube, kNan), InputError);
  for (int step = 0; step < 120; ++step) scene.Step();
  EXPECT_GT(LowestNodeHeight(*scene.cube), -world.solver_settings().contact_tolerance);
}

}  // namespace
}  // namespace taut
