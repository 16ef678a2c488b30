#include "constraints/curved_dual_metric.h"

#include "plugin/common.h"

namespace taut {

bool CurvedDualMetric::Factor(double h, const std::vector<IslandBody*>& bodies,
                              const std::vector<ConstraintSource*>& sources, const IslandRows& rows,
                              const VecX& lambda, const std::vector<VecX>& v) {
  curvature_.CollectLimitRows(h, bodies, sources, rows, lambda, v);
  if (curvature_.empty()) return false;
  for (IslandBody* body : bodies) body->ResetNewtonMatrix();
  curvature_.AddToNewtonMatrices(bodies);
  try {
    for (IslandBody* body : bodies) body->FactorNewtonMatrix();
  } catch (const SimulationError&) {
    return false;  // G is only a metric: A serves
  }
  return true;
}

void CurvedDualMetric::CalcFreeVelocities(const std::vector<IslandBody*>& bodies,
                                          const std::vector<VecX>& v, std::vector<VecX>& v_free) {
  v_free.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    v_free[b] = v[b] - bodies[b]->v_star();
    bodies[b]->ApplySystemMatrix(v_free[b], scratch_);
    bodies[b]->SolveNewton(scratch_);
    v_free[b] = v[b] - scratch_;
  }
}

void CurvedDualMetric::BuildW(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                              MatX& W) {
  const int m = rows.size();
  W.setZero(m, m);
  columns_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    const int body = static_cast<int>(b);
    const std::vector<int>& body_rows = rows.body_rows(body);
    const int n = 3 * bodies[b]->num_blocks();
    MatX& Y = columns_[b];
    Y.setZero(n, static_cast<Eigen::Index>(body_rows.size()));
    for (size_t i = 0; i < body_rows.size(); ++i) {
      rows[body_rows[i]].ForEachEntry([&](int row_body, int block, const Vec3& J) {
        if (row_body == body) Y.col(i).segment<3>(3 * block) += J;
      });
    }
    bodies[b]->SolveNewtonColumns(Y);
    // W(c, d) += J_c Y_d over the entries of row c on this body.
    for (size_t i = 0; i < body_rows.size(); ++i)
      rows[body_rows[i]].ForEachEntry([&](int row_body, int block, const Vec3& J) {
        if (row_body != body) return;
        for (size_t k = 0; k < body_rows.size(); ++k)
          W(body_rows[i], body_rows[k]) += J.dot(Y.col(k).segment<3>(3 * block));
      });
  }
  W = 0.5 * (W + W.transpose()).eval();
}

void CurvedDualMetric::AddImpulseVelocities(const IslandRows& rows, const VecX& lambda,
                                            std::vector<VecX>& v) const {
  for (size_t b = 0; b < columns_.size(); ++b) {
    const std::vector<int>& body_rows = rows.body_rows(static_cast<int>(b));
    for (size_t i = 0; i < body_rows.size(); ++i)
      if (lambda[body_rows[i]] != 0.0) v[b] += lambda[body_rows[i]] * columns_[b].col(i);
  }
}

}  // namespace taut
