// The columns Y_b = A_b^-1 J_b^T of the dual path, kept across the SQP iterations of one step.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/island_body.h"
#include "constraints/island_rows.h"

namespace taut {

// Per island body, the solved columns A_b^-1 J_b^T of its rows (docs/math.md §5.7: the SQP's
// W = J A^-1 J^T and v_QP = v* + Y lambda). A is fixed within a step, so a row that comes back in
// the next SQP iteration with the same key and the same J entries on the body (contact rows on a
// fixed normal, joint rows; not limit rows, whose J moves with x) keeps its column and only the
// other rows are solved, in one multi-column solve. Each column is A^-1 of its own right-hand
// side, so the result does not depend on which columns were kept.
class DelassusColumns {
 public:
  // Forgets every kept column (call at the start of each step: A changed).
  void Clear();
  // Y_b for every body b of the island and its rows in `rows` (body_rows order).
  void Build(const std::vector<IslandBody*>& bodies, const IslandRows& rows);
  // (3 num_blocks x rows of b) the columns of body b after Build.
  const MatX& Y(int b) const { return bodies_[b].Y; }
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
    MatX Y;                                             // columns of the current rows
    std::vector<ColumnSource> sources;                  // what each column of Y was solved for
    std::vector<std::pair<std::uint64_t, int>> by_key;  // (key, column), sorted by key
    MatX next;                                          // the next Build's Y, swapped in
    MatX fresh;                                         // right-hand sides of the columns to solve
    std::vector<ColumnSource> next_sources;
    std::vector<int> to_solve;  // columns of `next` solved in `fresh`
  };
  // The part of `row` on body `b`.
  static ColumnSource CalcSource(const ConstraintRow& row, int b);
  // Column of the kept Y solved for `source`, -1 if none.
  static int FindKept(const BodyColumns& body, const ColumnSource& source);

  std::vector<BodyColumns> bodies_;
  long columns_solved_ = 0;
  long columns_kept_ = 0;
};

}  // namespace taut
