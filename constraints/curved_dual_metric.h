// The dual path's curved QP metric (docs/math.md §5.7, "curved metric"): the SQP's QP at
// (v_k, lambda_k) with the Lagrangian's curvature instead of A alone,
//   min_v 1/2 (v - v_k)^T N (v - v_k) + g^T (v - v_k)   s.t. the rows linearized at x_k,
//   N = A + G,  G = h sum_c lambda_c [-d^2 C_c/dx^2]_+  (limit rows, negative modes clamped),
//   g = A (v_k - v*),
// whose dual is the papers' LCP with W = J N^-1 J^T and the free velocity
// v_free = v_k - N^-1 g in place of v*: v_QP = v_free + N^-1 J^T lambda_QP. At a fixed point
// (v_QP = v_k) stationarity is A (v - v*) = J^T lambda, the papers' KKT conditions, so the
// converged answer is unchanged; without G the SQP is a Gauss-Newton iteration that converges
// linearly at the rate the row curvature sets (half per iteration on the finger's held press).
// N is factored on the bodies' Newton matrices (the primal path's storage).
#pragma once

#include <vector>

#include "constraints/curvature_metric.h"
#include "constraints/island_body.h"
#include "constraints/island_rows.h"

namespace taut {

class CurvedDualMetric {
 public:
  // Stage: G at the rows (collected at v) with multipliers lambda, N_b = A_b + G_b factored.
  // False when no limit row pushes (G = 0: the papers' metric A serves) or a factorization
  // failed (N indefinite in round-off; A then serves too).
  bool Factor(double h, const std::vector<IslandBody*>& bodies,
              const std::vector<ConstraintSource*>& sources, const IslandRows& rows,
              const VecX& lambda, const std::vector<VecX>& v);
  // v_free_b = v_b - N_b^-1 A_b (v_b - v*_b).
  void CalcFreeVelocities(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v,
                          std::vector<VecX>& v_free);
  // Y_b = N_b^-1 J_b^T per body (kept for AddImpulseVelocities) and W = sum_b J_b Y_b (m x m,
  // symmetrized).
  void BuildW(const std::vector<IslandBody*>& bodies, const IslandRows& rows, MatX& W);
  // v_b += Y_b lambda (the rows of the last BuildW).
  void AddImpulseVelocities(const IslandRows& rows, const VecX& lambda, std::vector<VecX>& v) const;

 private:
  CurvatureMetric curvature_;
  VecX scratch_;
  std::vector<MatX> columns_;  // Y_b, 3 N_b x (rows of body b)
};

}  // namespace taut
