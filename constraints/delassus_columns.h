// The columns Y_b = A_b^-1 J_b^T of the dual path, kept across the SQP iterations of one step.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/island_body.h"
#include "constraints/island_rows.h"

namespace taut {

// Per island body, the solved columns of its rows and its Delassus block W_b = J_b A_b^-1 J_b^T
// (docs/math.md §5.7: the SQP's W = sum_b W_b and v_QP = v* + sum_b A_b^-1 J_b^T lambda_b).
// Two kinds of columns:
//   - bodies where half solves pay (IslandBody::HalfSolvesPay, chosen at the first Build of a
//     step: deformable bodies on SparseLdlt with few rows for the size of their factor):
//     Z_b = G_b J_b^T with A_b^-1 = G_b^T G_b, so W_b = Z_b^T Z_b and A_b^-1 J_b^T lambda =
//     G_b^T (Z_b lambda). The forward solve of a sparse column only runs along its
//     elimination-tree path, and the backward solve runs once per QP instead of once per row;
//   - the others (rigid bodies, multibodies, deformable bodies with many rows): Y_b = A_b^-1 J_b^T,
//     W_b = J_b Y_b.
// A is fixed within a step, so a row that comes back in the next SQP iteration with the same key
// and the same J entries on the body (contact rows on a fixed normal, joint rows; not limit rows,
// whose J moves with x) keeps its column, and its entries of W_b with the other kept rows; only
// the other rows are solved, in one multi-column solve. Each column is solved for its own
// right-hand side, so the result does not depend on which columns were kept.
class DelassusColumns {
 public:
  // Forgets every kept column (call at the start of each step: A changed).
  void Clear();
  // The columns and W_b of every body b of the island for its rows in `rows` (body_rows order).
  void Build(const std::vector<IslandBody*>& bodies, const IslandRows& rows);
  // (rows of b x rows of b) W_b = J_b A_b^-1 J_b^T after Build.
  const MatX& W(int b) const { return bodies_[b].W; }
  // v += A_b^-1 J_b^T lambda_b for body b (`body`), lambda_b(i) = lambda(body_rows[i]) over b's
  // rows (IslandRows::body_rows order); v has 3 num_blocks entries.
  void AddImpulseVelocity(int b, const IslandBody& body, const std::vector<int>& body_rows,
                          const VecX& lambda, VecX& v) const;
  // True when body b's columns are half solves Z_b (else Y_b = A_b^-1 J_b^T).
  bool half_solved(int b) const { return bodies_[b].half; }
  // Columns solved and kept by the Build calls since Clear (statistics for tests and benches).
  long columns_solved() const { return columns_solved_; }
  long columns_kept() const { return columns_kept_; }

 private:
  // A row's part on one body: what its column depends on besides A.
  struct ColumnSource {
    std::uint64_t key = 0;
    int count = 0;
    std::array<int, 2 * kMaxRowNodes> blocks{};
    std::array<Vec3, 2 * kMaxRowNodes> J{};
    bool operator==(const ColumnSource& o) const;
  };
  struct BodyColumns {
    bool half = false;                  // Y holds Z_b (half solves)
    int num_blocks = -1;                // the body's blocks at the last Build; -1 after Clear
    MatX Y;                             // columns of the current rows
    MatX W;                             // W_b of the current rows
    MatX next_W;                        // the next Build's W_b, swapped in
    std::vector<int> kept_from;         // column of the kept Y, -1 when solved
    std::vector<ColumnSource> sources;  // what each column of Y was solved for
    std::vector<std::pair<std::uint64_t, int>> by_key;  // (key, column), sorted by key
    MatX next;                                          // the next Build's Y, swapped in
    MatX fresh;                     // right-hand sides of the columns to solve (full solves)
    SparseColumns fresh_sparse;     // the same as entries (half solves)
    MatX fresh_solved;              // their half solves
    mutable VecX impulse;           // Z_b lambda
    mutable VecX impulse_velocity;  // G^T Z_b lambda
    std::vector<int> nonzero_rows;  // runs (start, end) of rows where a fresh column is nonzero
    std::vector<unsigned char> row_is_nonzero;  // (DOFs) scratch of BuildW's scan
    MatX gathered, gathered_fresh;              // those rows of Y and of fresh_solved
    MatX cross;                                 // Z^T Z_fresh
    std::vector<ColumnSource> next_sources;
    std::vector<int> to_solve;  // columns of `next` solved in `fresh`
  };
  // The part of `row` on body `b`.
  static ColumnSource CalcSource(const ConstraintRow& row, int b);
  // Column of the kept Y solved for `source`, -1 if none.
  static int FindKept(const BodyColumns& body, const ColumnSource& source);
  // The right-hand sides J^T of body.to_solve: body.fresh_sparse for half solves, else the dense
  // body.fresh (n_full rows).
  static void GatherFresh(int n_full, BodyColumns& body);
  // body.fresh <- its columns solved: Z = G J^T or Y = A^-1 J^T.
  static void SolveFresh(const IslandBody& island_body, BodyColumns& body);
  // body.next_W for the columns in body.next: entries between kept columns copied from body.W,
  // the others Z_i . Z_k (half solves) or J_i Y_k.
  static void BuildW(const IslandRows& rows, const std::vector<int>& body_rows, int b,
                     BodyColumns& body);

  std::vector<BodyColumns> bodies_;
  long columns_solved_ = 0;
  long columns_kept_ = 0;
};

}  // namespace taut
