// The dual path's curved QP metric (constraints/curved_dual_metric.h): W = J N^-1 J^T, the free
// velocity v_k - N^-1 A (v_k - v*) and the impulse velocities N^-1 J^T lambda for N = A + G, each
// against a dense solve; and through the world, the SQP in that metric ends where the papers'
// metric A ends, in fewer iterations.
#include "constraints/curved_dual_metric.h"

#include <gtest/gtest.h>

#include <memory>

#include "constraints/deformable_island_body.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kMetricH = 0.01;

// Limit rows, one per listed (node, J), on body 0; each row's curvature is weight * K_row, a
// fixed SPD 3x3 block on its node.
class CurvedRows final : public ConstraintSource {
 public:
  struct Entry {
    int node;
    Vec3 J;
    Mat3 K;
  };
  std::vector<Entry> entries;
  int AppendIslandRows(const IslandIterate& /*iterate*/,
                       std::vector<ConstraintRow>& rows) override {
    for (size_t i = 0; i < entries.size(); ++i) {
      ConstraintRow& row = rows.emplace_back();
      row.key = 100 + i;
      row.C = -0.01;
      row.body = 0;
      row.type = RowType::kStrainLimit;
      row.num_nodes = 1;
      row.nodes[0] = entries[i].node;
      row.J[0] = entries[i].J;
    }
    return static_cast<int>(entries.size());
  }
  void AddIslandCurvature(const IslandIterate& /*iterate*/, const ConstraintRow* rows,
                          const double* weights, int count, CurvatureSink& sink) const override {
    for (int c = 0; c < count; ++c) {
      const std::uint64_t i = rows[c].key - 100;
      if (weights[c] > 0.0)
        sink.AddBlock(0, entries[i].node, entries[i].node, weights[c] * entries[i].K);
    }
  }
  double CalcIslandViolationSum(const IslandIterate& /*iterate*/) const override { return 0.0; }
};

class CurvedDualMetricTest : public ::testing::Test {
 protected:
  CurvedDualMetricTest()
      : body_(std::make_unique<TetElementModel>(
                  std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.6, 0.2, 0.2), 3, 1, 1)),
                  Material{}),
              DeformableBodySettings{}),
        island_body_(body_) {
    body_.FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    body_.BeginStep(kMetricH, Vec3(0, 0, -9.81));
    n_ = 3 * island_body_.num_blocks();
    Mat3 K;
    K << 4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0;
    source_.entries = {{5, Vec3(1.0, 0.2, 0.0), 1e4 * K},
                       {9, Vec3(0.0, -0.5, 1.0), 3e4 * K},
                       {14, Vec3(0.3, 0.3, 0.3), 2e4 * K.transpose() * K}};
  }
  // Dense N = A + G on free DOFs (identity rows on pinned ones, which every solve zeroes).
  MatX DenseN(const VecX& lambda) const {
    MatX N = MatX::Zero(n_, n_);
    VecX e = VecX::Zero(n_), column;
    for (int i = 0; i < n_; ++i) {
      e[i] = 1.0;
      island_body_.ApplySystemMatrix(e, column);
      N.col(i) = column;
      e[i] = 0.0;
    }
    for (size_t c = 0; c < source_.entries.size(); ++c) {
      const int node = source_.entries[c].node;
      N.block<3, 3>(3 * node, 3 * node) += kMetricH * lambda[c] * source_.entries[c].K;
    }
    for (int i = 0; i < island_body_.num_blocks(); ++i)
      if (!island_body_.is_free_block(i)) {
        N.middleRows<3>(3 * i).setZero();
        N.middleCols<3>(3 * i).setZero();
        N.block<3, 3>(3 * i, 3 * i).setIdentity();
      }
    return N;
  }
  // The dense N^-1 rhs with pinned entries zeroed.
  VecX SolveDense(const MatX& N, VecX rhs) const {
    for (int i = 0; i < island_body_.num_blocks(); ++i)
      if (!island_body_.is_free_block(i)) rhs.segment<3>(3 * i).setZero();
    return N.ldlt().solve(rhs);
  }
  VecX Column(int c) const {
    VecX J = VecX::Zero(n_);
    J.segment<3>(3 * source_.entries[c].node) = source_.entries[c].J;
    return J;
  }

  DeformableBody body_;
  DeformableIslandBody island_body_;
  CurvedRows source_;
  IslandRows rows_;
  CurvedDualMetric metric_;
  int n_ = 0;
};

TEST_F(CurvedDualMetricTest, DelassusFreeAndImpulseVelocitiesMatchDenseSolves) {
  std::vector<IslandBody*> bodies{&island_body_};
  const std::vector<VecX> v{VecX::Zero(n_)};
  rows_.Collect(kMetricH, bodies, {&source_}, v, 1.0);
  ASSERT_EQ(rows_.size(), 3);
  const VecX lambda = (VecX(3) << 2.0, 0.5, 1.5).finished();
  ASSERT_TRUE(metric_.Factor(kMetricH, bodies, {&source_}, rows_, lambda, v));
  const MatX N = DenseN(lambda);

  MatX W;
  metric_.BuildW(bodies, rows_, W);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      const double expected = Column(i).dot(SolveDense(N, Column(k)));
      EXPECT_NEAR(W(i, k), expected, 1e-10 * std::abs(expected) + 1e-14) << i << ", " << k;
    }

  // v_free = v_k - N^-1 A (v_k - v*), at some v_k away from v*.
  std::vector<VecX> v_k{body_.v_star() + VecX::LinSpaced(n_, -0.2, 0.3)};
  for (int i = 0; i < island_body_.num_blocks(); ++i)
    if (!island_body_.is_free_block(i)) v_k[0].segment<3>(3 * i) = body_.v_star().segment<3>(3 * i);
  std::vector<VecX> v_free;
  metric_.CalcFreeVelocities(bodies, v_k, v_free);
  VecX a_dv;
  island_body_.ApplySystemMatrix(v_k[0] - body_.v_star(), a_dv);
  const VecX expected_free = v_k[0] - SolveDense(N, a_dv);
  EXPECT_LE((v_free[0] - expected_free).norm(), 1e-10 * expected_free.norm());

  // v += N^-1 J^T lambda_QP.
  const VecX lambda_qp = (VecX(3) << 0.7, -0.2, 1.1).finished();
  std::vector<VecX> v_qp{VecX::Zero(n_)};
  metric_.AddImpulseVelocities(rows_, lambda_qp, v_qp);
  const VecX expected_qp =
      SolveDense(N, lambda_qp[0] * Column(0) + lambda_qp[1] * Column(1) + lambda_qp[2] * Column(2));
  EXPECT_LE((v_qp[0] - expected_qp).norm(), 1e-10 * expected_qp.norm());
}

TEST_F(CurvedDualMetricTest, NoPushingLimitRowMeansThePapersMetric) {
  std::vector<IslandBody*> bodies{&island_body_};
  const std::vector<VecX> v{VecX::Zero(n_)};
  rows_.Collect(kMetricH, bodies, {&source_}, v, 1.0);
  EXPECT_FALSE(metric_.Factor(kMetricH, bodies, {&source_}, rows_, VecX::Zero(3), v));
  EXPECT_FALSE(metric_.Factor(kMetricH, bodies, {&source_}, rows_,
                              (VecX(3) << -1.0, 0.0, -2.0).finished(), v));
}

// A soft bar hanging from one end under a load, +-2 % isotropic limits, the papers' dual path:
// with the curved metric the SQP ends at the same state (the same KKT conditions) in fewer
// iterations (Gauss-Newton in A converges only linearly where the rows curve).
struct LoadedBar {
  BulletWorldHolder holder;
  DeformableBody* body = nullptr;
  std::vector<int> tip;

  explicit LoadedBar(bool curvature) {
    DeformableBodySettings settings;
    settings.material = {2e3, 0.3, 1000.0};
    settings.mass_damping = 2.0;
    body = holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.3, 0.05, 0.05), 6, 1, 1), settings);
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    for (int i = 0; i < body->num_nodes(); ++i)
      if (body->model().rest_positions()[3 * i] > 0.3 - 1e-9) tip.push_back(i);
    holder.world.SetStrainLimits(body, StrainLimitSettings::Isotropic(0.98, 1.02));
    SqpSettings& sqp = holder.world.mutable_solver_settings();
    sqp.solver = IslandSolverKind::kDual;
    sqp.max_iterations = 40;
    sqp.dual_curvature = curvature;
  }
  // Steps with a sideways and downward tip load; returns the summed SQP iterations and counts
  // the unconverged steps.
  int Run(int steps, int& unconverged) {
    int iterations = 0;
    for (int step = 0; step < steps; ++step) {
      for (int i : tip) body->AddNodeForce(i, Vec3(0.5, 0.3, -1.0));
      holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
      iterations += holder.world.last_step_stats().sqp_iterations;
      unconverged += holder.world.last_step_stats().converged ? 0 : 1;
    }
    return iterations;
  }
};

TEST(CurvedDualMetricWorldTest, SameStateInFewerSqpIterations) {
  LoadedBar papers(false), curved(true);
  int unconverged_papers = 0, unconverged_curved = 0;
  const int iterations_papers = papers.Run(60, unconverged_papers);
  const int iterations_curved = curved.Run(60, unconverged_curved);
  double gap = 0.0;
  for (int i = 0; i < papers.body->num_nodes(); ++i)
    gap = std::max(gap, (papers.body->node_position(i) - curved.body->node_position(i)).norm());
  std::printf(
      "[ loaded bar, 60 steps, dual path ] SQP iterations: metric A %d (%d unconverged), "
      "A + G %d (%d unconverged); largest node distance %.2e m\n",
      iterations_papers, unconverged_papers, iterations_curved, unconverged_curved, gap);
  EXPECT_EQ(unconverged_curved, 0);
  EXPECT_LE(unconverged_curved, unconverged_papers);
  EXPECT_LT(iterations_curved, iterations_papers);
  EXPECT_GT(curved.holder.world.last_step_stats().rows_strain, 0);
  EXPECT_LT(gap, 1e-3);
}

}  // namespace
}  // namespace taut
