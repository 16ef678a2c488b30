// DelassusColumns (constraints/delassus_columns.h): every column is A^-1 J^T of its own row, a
// row that comes back with the same key and J keeps its column, and a row whose J moved is
// solved again.
#include "constraints/delassus_columns.h"

#include <gtest/gtest.h>

#include <memory>

#include "constraints/deformable_island_body.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kDelassusH = 0.01;

// Emits one row per (key, node, J) entry given, on body 0.
class ListedRows final : public ConstraintSource {
 public:
  struct Entry {
    std::uint64_t key;
    int node;
    Vec3 J;
  };
  std::vector<Entry> entries;
  int AppendIslandRows(const IslandIterate& /*iterate*/,
                       std::vector<ConstraintRow>& rows) override {
    for (const Entry& e : entries) {
      ConstraintRow& row = rows.emplace_back();
      row.key = e.key;
      row.C = 0.5;
      row.body = 0;
      row.type = RowType::kContact;
      row.num_nodes = 1;
      row.nodes[0] = e.node;
      row.J[0] = e.J;
    }
    return static_cast<int>(entries.size());
  }
  double CalcIslandViolationSum(const IslandIterate& /*iterate*/) const override { return 0.0; }
};

class DelassusColumnsTest : public ::testing::Test {
 protected:
  DelassusColumnsTest()
      : body_(std::make_unique<TetElementModel>(
                  std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.6, 0.2, 0.2), 3, 1, 1)),
                  Material{}),
              DeformableBodySettings{}),
        island_body_(body_) {
    body_.BeginStep(kDelassusH, Vec3(0, 0, -9.81));
  }
  // Rows of `source` collected at v = 0, then the columns built.
  void Build(ListedRows& source) {
    std::vector<IslandBody*> bodies{&island_body_};
    rows_.Collect(kDelassusH, bodies, {&source}, {VecX::Zero(3 * island_body_.num_blocks())}, 1.0);
    columns_.Build(bodies, rows_);
  }
  // A^-1 e_node J, solved on its own.
  VecX SolveOne(int node, const Vec3& J) {
    VecX rhs = VecX::Zero(3 * island_body_.num_blocks());
    rhs.segment<3>(3 * node) = J;
    MatX column = rhs;
    island_body_.SolveSystemColumns(column);
    return column.col(0);
  }

  // W_b(i, k) = J_i A^-1 J_k^T and AddImpulseVelocity = A^-1 sum_i J_i^T lambda_i for the rows of
  // `source` as last built, each column solved on its own.
  void ExpectDelassusOfRows(const ListedRows& source) {
    const std::vector<int>& body_rows = rows_.body_rows(0);
    const int m = static_cast<int>(body_rows.size());
    const MatX& W = columns_.W(0);
    ASSERT_EQ(W.rows(), m);
    ASSERT_EQ(W.cols(), m);
    VecX lambda(m), expected_v = VecX::Zero(3 * island_body_.num_blocks());
    for (int k = 0; k < m; ++k) {
      const ListedRows::Entry& e_k = source.entries[body_rows[k]];
      const VecX column = SolveOne(e_k.node, e_k.J);
      lambda[k] = 0.5 + k;
      expected_v += lambda[k] * column;
      for (int i = 0; i < m; ++i) {
        const ListedRows::Entry& e_i = source.entries[body_rows[i]];
        const double expected = e_i.J.dot(column.segment<3>(3 * e_i.node));
        EXPECT_NEAR(W(i, k), expected, 1e-12 * std::abs(W(k, k)))
            << "rows " << e_i.key << ", " << e_k.key;
      }
    }
    // lambda is indexed by island row here: body 0's rows are the island's rows.
    VecX lambda_island = VecX::Zero(rows_.size());
    for (int k = 0; k < m; ++k) lambda_island[body_rows[k]] = lambda[k];
    VecX v = VecX::Zero(expected_v.size());
    columns_.AddImpulseVelocity(0, island_body_, body_rows, lambda_island, v);
    EXPECT_LT((v - expected_v).norm(), 1e-12 * expected_v.norm());
  }

  DeformableBody body_;
  DeformableIslandBody island_body_;
  IslandRows rows_;
  DelassusColumns columns_;
};

TEST_F(DelassusColumnsTest, KeepsColumnsOfUnchangedRowsAndSolvesTheOthers) {
  ListedRows source;
  source.entries = {{11, 5, Vec3::UnitZ()}, {12, 6, Vec3::UnitX()}, {13, 7, Vec3(0, 0.6, 0.8)}};
  Build(source);
  EXPECT_EQ(columns_.columns_solved(), 3);
  EXPECT_EQ(columns_.columns_kept(), 0);
  EXPECT_TRUE(columns_.half_solved(0));  // a deformable body on SparseLdlt
  ExpectDelassusOfRows(source);
  // Next iteration: row 12's J moved, row 14 is new, 13 and 11 come back in another order.
  source.entries = {{13, 7, Vec3(0, 0.6, 0.8)},
                    {12, 6, Vec3(0.8, 0.6, 0)},
                    {14, 2, Vec3::UnitY()},
                    {11, 5, Vec3::UnitZ()}};
  Build(source);
  EXPECT_EQ(columns_.columns_solved(), 5);
  EXPECT_EQ(columns_.columns_kept(), 2);
  ExpectDelassusOfRows(source);
}

TEST_F(DelassusColumnsTest, ManyRowsForTheFactorTakeFullColumnsWithTheSameDelassus) {
  // Six rows per node, twice as many rows as DOFs: rows x DOFs exceed 4 nnz(L) (L has fewer than
  // n^2 / 2 entries), so full columns Y = A^-1 J^T are cheaper than half solves.
  ListedRows source;
  std::uint64_t key = 100;
  for (int node = 0; node < island_body_.num_blocks(); ++node)
    for (const Vec3& J : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitY()), Vec3(Vec3::UnitZ()),
                          Vec3(0.6, 0.8, 0.0), Vec3(0.0, 0.6, 0.8), Vec3(0.8, 0.0, 0.6)})
      source.entries.push_back({key++, node, J});
  ASSERT_FALSE(island_body_.HalfSolvesPay(static_cast<int>(source.entries.size())));
  ASSERT_TRUE(island_body_.HalfSolvesPay(3));
  Build(source);
  EXPECT_FALSE(columns_.half_solved(0));
  ExpectDelassusOfRows(source);
}

TEST_F(DelassusColumnsTest, ClearForgetsTheKeptColumns) {
  ListedRows source;
  source.entries = {{21, 3, Vec3::UnitZ()}};
  Build(source);
  columns_.Clear();
  // A new step: A changed, so the same row is solved again.
  body_.BeginStep(kDelassusH, Vec3(0, 0, -9.81));
  Build(source);
  EXPECT_EQ(columns_.columns_solved(), 1);
  EXPECT_EQ(columns_.columns_kept(), 0);
  ExpectDelassusOfRows(source);
}

}  // namespace
}  // namespace taut
