#include "constraints/delassus_columns.h"

#include <algorithm>

namespace taut {

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
// placed; then the new columns become the kept ones.
void DelassusColumns::Build(const std::vector<IslandBody*>& bodies, const IslandRows& rows) {
  if (bodies_.size() < bodies.size()) bodies_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    BodyColumns& body = bodies_[b];
    const std::vector<int>& body_rows = rows.body_rows(static_cast<int>(b));
    const int n = 3 * bodies[b]->num_blocks(), m = static_cast<int>(body_rows.size());
    body.next.resize(n, m);
    body.next_sources.resize(m);
    body.to_solve.clear();
    for (int k = 0; k < m; ++k) {
      body.next_sources[k] = CalcSource(rows[body_rows[k]], static_cast<int>(b));
      const int kept = body.Y.rows() == n ? FindKept(body, body.next_sources[k]) : -1;
      if (kept >= 0) {
        body.next.col(k) = body.Y.col(kept);
        columns_kept_++;
      } else {
        body.to_solve.push_back(k);
      }
    }
    const int num_fresh = static_cast<int>(body.to_solve.size());
    if (num_fresh > 0) {
      body.fresh.setZero(n, num_fresh);
      for (int f = 0; f < num_fresh; ++f) {
        const ColumnSource& s = body.next_sources[body.to_solve[f]];
        for (int i = 0; i < s.count; ++i) body.fresh.col(f).segment<3>(3 * s.blocks[i]) += s.J[i];
      }
      bodies[b]->SolveSystemColumns(body.fresh);
      for (int f = 0; f < num_fresh; ++f) body.next.col(body.to_solve[f]) = body.fresh.col(f);
      columns_solved_ += num_fresh;
    }
    std::swap(body.Y, body.next);
    std::swap(body.sources, body.next_sources);
    body.by_key.resize(m);
    for (int k = 0; k < m; ++k) body.by_key[k] = {body.sources[k].key, k};
    std::sort(body.by_key.begin(), body.by_key.end());
  }
}

}  // namespace taut
