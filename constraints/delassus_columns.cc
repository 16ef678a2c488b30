#include "constraints/delassus_columns.h"

#include <algorithm>

#include "plugin/dense_kernels.h"

namespace taut {
namespace {

// out = a^T b (a: d x m, b: d x k), the depth summed in fixed chunks (plugin/dense_kernels.h).
void MultiplyTransposedByChunks(const MatX& a, const MatX& b, MatX& out) {
  out.resize(a.cols(), b.cols());
  ActiveDenseKernels().multiply_transposed_by_chunks(
      a.data(), static_cast<int>(a.rows()), b.data(), static_cast<int>(b.rows()),
      static_cast<int>(a.rows()), static_cast<int>(a.cols()), static_cast<int>(b.cols()),
      out.data(), static_cast<int>(out.rows()));
}

// out = a^T a by rank updates of fixed chunks, both triangles.
void MultiplyGramByChunks(const MatX& a, MatX& out) {
  out.resize(a.cols(), a.cols());
  ActiveDenseKernels().gram_by_chunks(a.data(), static_cast<int>(a.rows()),
                                      static_cast<int>(a.rows()), static_cast<int>(a.cols()),
                                      out.data(), static_cast<int>(out.rows()));
}

}  // namespace

bool DelassusColumns::ColumnSource::operator==(const ColumnSource& o) const {
  if (key != o.key || count != o.count) return false;
  for (int i = 0; i < count; ++i)
    if (blocks[i] != o.blocks[i] || J[i] != o.J[i]) return false;
  return true;
}

void DelassusColumns::Clear() {
  for (BodyColumns& body : bodies_) {
    body.sources.clear();
    body.by_key.clear();
    body.num_blocks = -1;  // the kind of columns is chosen again
  }
  columns_solved_ = 0;
  columns_kept_ = 0;
}

DelassusColumns::ColumnSource DelassusColumns::CalcSource(const ConstraintRow& row, int b) {
  ColumnSource source;
  source.key = row.key;
  row.ForEachEntry([&](int on, int block, const Vec3& J) {
    if (on != b) return;
    source.blocks[source.count] = block;
    source.J[source.count] = J;
    source.count++;
  });
  return source;
}

int DelassusColumns::FindKept(const BodyColumns& body, const ColumnSource& source) {
  auto it =
      std::lower_bound(body.by_key.begin(), body.by_key.end(), std::make_pair(source.key, -1));
  for (; it != body.by_key.end() && it->first == source.key; ++it)
    if (body.sources[it->second] == source) return it->second;
  return -1;
}

// Per body: kept columns copied, the others scattered as J^T into `fresh`, solved at once, and
// placed; W_b built; then the new columns become the kept ones.
void DelassusColumns::Build(const std::vector<IslandBody*>& bodies, const IslandRows& rows) {
  if (bodies_.size() < bodies.size()) bodies_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    BodyColumns& body = bodies_[b];
    const std::vector<int>& body_rows = rows.body_rows(static_cast<int>(b));
    const int n_full = 3 * bodies[b]->num_blocks(), m = static_cast<int>(body_rows.size());
    if (body.num_blocks != bodies[b]->num_blocks()) {
      // The first Build of a step (or another body at this index): nothing to keep, and the
      // kind of columns is chosen for the step by the body's cost rule.
      body.half = bodies[b]->HalfSolvesPay(m);
      body.num_blocks = bodies[b]->num_blocks();
      body.sources.clear();
      body.by_key.clear();
    }
    const bool half = body.half;
    const bool keep = !body.sources.empty();
    body.next_sources.resize(m);
    body.kept_from.assign(m, -1);
    body.to_solve.clear();
    for (int k = 0; k < m; ++k) {
      body.next_sources[k] = CalcSource(rows[body_rows[k]], static_cast<int>(b));
      const int kept = keep ? FindKept(body, body.next_sources[k]) : -1;
      body.kept_from[k] = kept;
      if (kept >= 0)
        columns_kept_++;
      else
        body.to_solve.push_back(k);
    }
    const int num_fresh = static_cast<int>(body.to_solve.size());
    if (num_fresh > 0) {
      GatherFresh(n_full, body);
      SolveFresh(*bodies[b], body);
      columns_solved_ += num_fresh;
    }
    const MatX& solved = half ? body.fresh_solved : body.fresh;
    const Eigen::Index n = num_fresh > 0 ? solved.rows() : body.Y.rows();
    body.next.resize(n, m);
    int f = 0;
    for (int k = 0; k < m; ++k) {
      if (body.kept_from[k] >= 0)
        body.next.col(k) = body.Y.col(body.kept_from[k]);
      else
        body.next.col(k) = solved.col(f++);
    }
    BuildW(rows, body_rows, static_cast<int>(b), body);
    std::swap(body.Y, body.next);
    std::swap(body.W, body.next_W);
    std::swap(body.sources, body.next_sources);
    body.by_key.resize(m);
    for (int k = 0; k < m; ++k) body.by_key[k] = {body.sources[k].key, k};
    std::sort(body.by_key.begin(), body.by_key.end());
  }
}

void DelassusColumns::GatherFresh(int n_full, BodyColumns& body) {
  // Half solves take the J^T columns as entries (a few DOFs each); full solves a dense block.
  const int num_fresh = static_cast<int>(body.to_solve.size());
  if (body.half) {
    body.fresh_sparse.Clear();
    for (int f = 0; f < num_fresh; ++f) {
      const ColumnSource& s = body.next_sources[body.to_solve[f]];
      for (int i = 0; i < s.count; ++i)
        for (int d = 0; d < 3; ++d) body.fresh_sparse.Add(3 * s.blocks[i] + d, s.J[i][d]);
      body.fresh_sparse.EndColumn();
    }
    return;
  }
  body.fresh.setZero(n_full, num_fresh);
  for (int f = 0; f < num_fresh; ++f) {
    const ColumnSource& s = body.next_sources[body.to_solve[f]];
    for (int i = 0; i < s.count; ++i) body.fresh.col(f).segment<3>(3 * s.blocks[i]) += s.J[i];
  }
}

void DelassusColumns::SolveFresh(const IslandBody& island_body, BodyColumns& body) {
  if (body.half)
    island_body.HalfSolveSystemColumns(body.fresh_sparse, body.fresh_solved);
  else
    island_body.SolveSystemColumns(body.fresh);
}

// Half solves: W_b(i, k) = Z_i . Z_k, only over the rows where a fresh column is nonzero (the
// union of their elimination-tree paths). Full columns: W_b(i, k) = J_i Y_k, J sparse over a
// row's blocks (a 1x3 times 3-row product per block).
void DelassusColumns::BuildW(const IslandRows& rows, const std::vector<int>& body_rows, int b,
                             BodyColumns& body) {
  const int m = static_cast<int>(body_rows.size());
  body.next_W.resize(m, m);
  if (!body.half) {
    for (int i = 0; i < m; ++i) {
      body.next_W.row(i).setZero();
      rows[body_rows[i]].ForEachEntry([&](int on, int block, const Vec3& J) {
        if (on == b)
          body.next_W.row(i).noalias() += J.transpose() * body.next.middleRows<3>(3 * block);
      });
    }
    return;
  }
  for (int k = 0; k < m; ++k) {
    if (body.kept_from[k] < 0) continue;
    for (int i = 0; i < m; ++i)
      if (body.kept_from[i] >= 0) body.next_W(i, k) = body.W(body.kept_from[i], body.kept_from[k]);
  }
  const int num_fresh = static_cast<int>(body.to_solve.size());
  if (num_fresh == 0) return;
  // Runs [start, end) of rows where a fresh column is nonzero (whole supernodes of the paths).
  const MatX& fresh = body.fresh_solved;
  const int n = static_cast<int>(fresh.rows());
  std::vector<unsigned char>& nonzero = body.row_is_nonzero;
  nonzero.assign(n, 0);
  for (int f = 0; f < num_fresh; ++f) {  // column by column: contiguous reads
    const double* column = fresh.col(f).data();
    for (int r = 0; r < n; ++r) nonzero[r] |= static_cast<unsigned char>(column[r] != 0.0);
  }
  std::vector<int>& runs = body.nonzero_rows;
  runs.clear();
  int num_nonzero = 0;
  for (int r = 0; r < n; ++r) {
    if (!nonzero[r]) continue;
    if (!runs.empty() && runs.back() == r)
      runs.back() = r + 1;
    else
      runs.insert(runs.end(), {r, r + 1});
    ++num_nonzero;
  }
  body.gathered.resize(num_nonzero, m);
  body.gathered_fresh.resize(num_nonzero, num_fresh);
  for (size_t q = 0, at = 0; q < runs.size(); q += 2) {
    const int start = runs[q], length = runs[q + 1] - runs[q];
    body.gathered.middleRows(at, length) = body.next.middleRows(start, length);
    body.gathered_fresh.middleRows(at, length) = fresh.middleRows(start, length);
    at += length;
  }
  if (num_fresh == m) {  // every column fresh: W_b = Z^T Z, one triangle (half the products)
    MultiplyGramByChunks(body.gathered, body.next_W);
    return;
  }
  // (m x num_fresh) Z^T Z_fresh: the fresh columns of W_b and, by symmetry, its fresh rows.
  MultiplyTransposedByChunks(body.gathered, body.gathered_fresh, body.cross);
  for (int f = 0; f < num_fresh; ++f) {
    const int k = body.to_solve[f];
    body.next_W.col(k) = body.cross.col(f);
    body.next_W.row(k) = body.cross.col(f).transpose();
  }
}

void DelassusColumns::AddImpulseVelocity(int b, const IslandBody& body,
                                         const std::vector<int>& body_rows, const VecX& lambda,
                                         VecX& v) const {
  const BodyColumns& columns = bodies_[b];
  if (!columns.half) {
    for (size_t i = 0; i < body_rows.size(); ++i) v += columns.Y.col(i) * lambda[body_rows[i]];
    return;
  }
  if (body_rows.empty()) return;
  columns.impulse.setZero(columns.Y.rows());
  for (size_t i = 0; i < body_rows.size(); ++i)
    columns.impulse += columns.Y.col(i) * lambda[body_rows[i]];
  body.CompleteHalfSolve(columns.impulse, columns.impulse_velocity);
  v += columns.impulse_velocity;
}

}  // namespace taut
