// Element blocks of the primal path's Newton matrix: ImplicitSystem::AddNewtonElementBlock (through
// the element's value map) adds exactly what one AddNewtonBlock per node pair adds, entries on
// fixed nodes dropped, for tets and hexes; CurvatureMetric's product G u and its part of H agree
// with the dense sum of its blocks.
#include "constraints/curvature_metric.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "constraints/deformable_island_body.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/hex_voxelizer.h"

namespace taut {
namespace {

// A random symmetric 3k x 3k block.
MatX RandomSymmetricBlock(int k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX B(3 * k, 3 * k);
  for (int i = 0; i < B.size(); ++i) B.data()[i] = u(rng);
  return B + B.transpose();
}

VecX RandomVector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// A body with its nodes at x = 0 fixed, stepped once so its system A is assembled.
struct SteppedBody {
  BulletWorldHolder holder;
  DeformableBody* body = nullptr;

  explicit SteppedBody(bool hex) {
    DeformableBodySettings settings;
    settings.name = hex ? "hexes" : "tets";
    settings.material = {5e3, 0.3, 1000.0};
    body = hex ? holder.world.AddHexBody(MakeBoxHexLattice(Vec3(0.3, 0.1, 0.1), 3, 1, 1), settings)
               : holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.3, 0.1, 0.1), 3, 1, 1), settings);
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  }
  // (H - A) u of the body's Newton matrix.
  VecX NewtonMinusSystemTimes(const VecX& u) const {
    VecX Hu, Au;
    body->system().MultiplyNewton(u, Hu);
    body->system().Multiply(u, Au);
    return Hu - Au;
  }
  // Dense sum_e B_e over the element nodes, rows and columns of fixed nodes zeroed.
  MatX DenseSum(const std::vector<MatX>& blocks) const {
    const ElementModel& model = body->model();
    const int k = model.nodes_per_element();
    MatX G = MatX::Zero(3 * body->num_nodes(), 3 * body->num_nodes());
    for (int e = 0; e < model.num_elements(); ++e) {
      const int* nodes = model.element_nodes(e);
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b)
          G.block<3, 3>(3 * nodes[a], 3 * nodes[b]) += blocks[e].block<3, 3>(3 * a, 3 * b);
    }
    for (int i = 0; i < body->num_nodes(); ++i)
      if (body->node_kind(i) != NodeKind::kFree) {
        G.middleRows<3>(3 * i).setZero();
        G.middleCols<3>(3 * i).setZero();
      }
    return G;
  }
};

void ExpectElementBlocksMatchNodeBlocks(bool hex) {
  SteppedBody s(hex);
  const ElementModel& model = s.body->model();
  const int k = model.nodes_per_element();
  std::mt19937 rng(hex ? 7 : 3);
  std::vector<MatX> blocks;
  for (int e = 0; e < model.num_elements(); ++e) blocks.push_back(RandomSymmetricBlock(k, rng));
  const VecX u = RandomVector(3 * s.body->num_nodes(), rng);
  ImplicitSystem& system = s.body->mutable_system();

  system.ResetNewtonMatrix();
  for (int e = 0; e < model.num_elements(); ++e) system.AddNewtonElementBlock(e, blocks[e]);
  const VecX by_element = s.NewtonMinusSystemTimes(u);

  system.ResetNewtonMatrix();
  for (int e = 0; e < model.num_elements(); ++e) {
    const int* nodes = model.element_nodes(e);
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        system.AddNewtonBlock(nodes[a], nodes[b], blocks[e].block<3, 3>(3 * a, 3 * b));
  }
  const VecX by_pair = s.NewtonMinusSystemTimes(u);

  const VecX dense = s.DenseSum(blocks) * u;
  ASSERT_GT(dense.norm(), 1.0);
  EXPECT_LT((by_element - dense).norm(), 1e-12 * dense.norm());
  EXPECT_LT((by_pair - dense).norm(), 1e-12 * dense.norm());
}

TEST(CurvatureMetricTest, ElementBlocksAddWhatNodePairBlocksAddOnTets) {
  ExpectElementBlocksMatchNodeBlocks(/*hex=*/false);
}

TEST(CurvatureMetricTest, ElementBlocksAddWhatNodePairBlocksAddOnHexes) {
  ExpectElementBlocksMatchNodeBlocks(/*hex=*/true);
}

TEST(CurvatureMetricTest, ProductAndNewtonPartAreTheDenseSumOfItsBlocks) {
  SteppedBody s(/*hex=*/false);
  const ElementModel& model = s.body->model();
  std::mt19937 rng(11);
  // Element blocks on every element, plus one node-pair block between two free nodes.
  CurvatureMetric metric;
  std::vector<MatX> blocks;
  for (int e = 0; e < model.num_elements(); ++e) {
    blocks.push_back(RandomSymmetricBlock(4, rng));
    metric.AddElementBlock(0, e, model.element_nodes(e), blocks.back());
  }
  const int a = model.element_nodes(model.num_elements() - 1)[0];
  const int b = model.element_nodes(model.num_elements() - 1)[1];
  ASSERT_EQ(s.body->node_kind(a), NodeKind::kFree);
  ASSERT_EQ(s.body->node_kind(b), NodeKind::kFree);
  const Mat3 pair = Mat3::Random();
  metric.AddBlock(0, a, b, pair);
  metric.AddBlock(0, b, a, pair.transpose());
  EXPECT_FALSE(metric.empty());

  MatX G = s.DenseSum(blocks);
  G.block<3, 3>(3 * a, 3 * b) += pair;
  G.block<3, 3>(3 * b, 3 * a) += pair.transpose();
  // u zero on fixed nodes: the solver zeroes those blocks of every product itself.
  VecX u = RandomVector(3 * s.body->num_nodes(), rng);
  for (int i = 0; i < s.body->num_nodes(); ++i)
    if (s.body->node_kind(i) != NodeKind::kFree) u.segment<3>(3 * i).setZero();
  const VecX expected = G * u;
  std::vector<VecX> us = {u}, out = {VecX::Zero(u.size())};
  metric.AddTimes(us, out);
  for (int i = 0; i < s.body->num_nodes(); ++i)
    if (s.body->node_kind(i) != NodeKind::kFree) out[0].segment<3>(3 * i).setZero();
  EXPECT_LT((out[0] - expected).norm(), 1e-12 * expected.norm());

  DeformableIslandBody island_body(*s.body);
  std::vector<IslandBody*> bodies = {&island_body};
  island_body.ResetNewtonMatrix();
  metric.AddToNewtonMatrices(bodies);
  const VecX newton_part = s.NewtonMinusSystemTimes(u);
  EXPECT_LT((newton_part - expected).norm(), 1e-12 * expected.norm());

  metric.Clear();
  EXPECT_TRUE(metric.empty());
}

TEST(CurvatureMetricTest, ClampingReplacesOnlyIndefiniteElementBlocksByTheirPsdPart) {
  // A positive definite block stays bit for bit; an indefinite one becomes V max(Lambda, 0) V^T:
  // positive semi-definite, the same on its non-negative eigenvectors, zero on the negative ones.
  std::mt19937 rng(5);
  const MatX random = RandomSymmetricBlock(4, rng);
  const MatX definite = random * random.transpose() + MatX::Identity(12, 12);
  MatX indefinite = RandomSymmetricBlock(4, rng);
  const Eigen::SelfAdjointEigenSolver<MatX> before(indefinite);
  ASSERT_LT(before.eigenvalues().minCoeff(), -0.1);
  ASSERT_GT(before.eigenvalues().maxCoeff(), 0.1);
  const int nodes[4] = {0, 1, 2, 3};
  CurvatureMetric metric;
  metric.AddElementBlock(0, 0, nodes, definite);
  metric.AddElementBlock(0, 1, nodes, indefinite);
  EXPECT_EQ(metric.ClampIndefiniteElementBlocks(), 1);
  // Both blocks sit on the same four nodes of body 0: column j of G is G e_j = (B_0 + B_1) e_j.
  MatX G(12, 12);
  for (int j = 0; j < 12; ++j) {
    std::vector<VecX> u = {VecX::Unit(12, j)}, out = {VecX::Zero(12)};
    metric.AddTimes(u, out);
    G.col(j) = out[0];
  }
  const MatX clamped = G - definite;
  EXPECT_LT((clamped - clamped.transpose()).norm(), 1e-12 * clamped.norm());
  const Eigen::SelfAdjointEigenSolver<MatX> after(clamped);
  EXPECT_GT(after.eigenvalues().minCoeff(), -1e-12 * after.eigenvalues().maxCoeff());
  for (int i = 0; i < 12; ++i) {
    const VecX q = before.eigenvectors().col(i);
    const double expected = std::max(0.0, before.eigenvalues()[i]);
    EXPECT_NEAR(q.dot(clamped * q), expected, 1e-10) << "eigenvalue " << before.eigenvalues()[i];
  }
  EXPECT_EQ(metric.ClampIndefiniteElementBlocks(), 0);  // nothing left to clamp
}

}  // namespace
}  // namespace taut
