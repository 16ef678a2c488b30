#include "constraints/frozen_island_lcp.h"

#include <limits>
#include <utility>

#include "constraints/lcp_residual.h"

namespace taut {

FrozenIslandLcp::FrozenIslandLcp(MatX W, VecX q0, std::vector<PgsRow> rows, VecX lambda0,
                                 ToolJacobian J_t)
    : W_(std::move(W)),
      q0_(std::move(q0)),
      lambda0_(std::move(lambda0)),
      rows_(std::move(rows)),
      J_t_(std::move(J_t)) {
  ValidateLcpProblem(W_, q0_, rows_, lambda0_);
  TAUT_DEMAND(J_t_.rows() == size() && J_t_.allFinite(), "FrozenIslandLcp: tool Jacobian has ",
              J_t_.rows(), " rows for ", size(), " LCP rows, or a non-finite entry");
  q_.resize(size());
  w_.resize(size());
  lambda_ = lambda0_;
}

FrozenIslandLcp::Result FrozenIslandLcp::Solve(const ToolTwist& u, const PgsSettings& settings) {
  TAUT_DEMAND(u.allFinite(), "FrozenIslandLcp::Solve: tool twist (", u.transpose(),
              ") is not finite");
  Result result;
  // (H1): q = q0 + J_t u, then PGS from the last lambda.
  q_.noalias() = J_t_ * u;
  q_ += q0_;
  PgsSettings pgs = settings;
  pgs.validate_input = false;  // validated once at construction; W and rows never change
  pgs.w_workspace = &w_;
  result.pgs = SolvePgs(W_, q_, rows_, lambda_, pgs);
  // (H2): p = J_t^T lambda.
  result.impulse.noalias() = J_t_.transpose() * lambda_;
  return result;
}

namespace {
// Y_b = A_b^-1 J_b^T (3 num_blocks x rows of b, body_rows order) without changing the body: a
// deformable's held factor must be this step's A (a solve that would factor is refused).
MatX SolveColumnsReadOnly(const IslandBody& body, int b, const IslandRows& rows) {
  const std::vector<int>& body_rows = rows.body_rows(b);
  MatX Y = MatX::Zero(3 * body.num_blocks(), static_cast<int>(body_rows.size()));
  for (size_t i = 0; i < body_rows.size(); ++i)
    rows[body_rows[i]].ForEachEntry([&](int on, int block, const Vec3& J) {
      if (on == b) Y.col(static_cast<int>(i)).segment<3>(3 * block) += J;
    });
  if (Y.cols() == 0) return Y;
  const DeformableBody* deformable = body.deformable();
  if (deformable == nullptr) {
    body.SolveSystemColumns(Y);  // rigid: A = diag(m I, I_world), nothing held
    return Y;
  }
  TAUT_DEMAND(deformable->system().factor_is_current(), "body '", deformable->name(),
              "': its held factor is not this step's A (it was not stepped, or its "
              "unconstrained solve reused an earlier factor and no solve factored A since): "
              "freezing the island would have to factor A and change the body; turn off "
              "factor_reuse for this body");
  deformable->system().SolveColumns(Y);
  return Y;
}

// W = sum_b J_b Y_b, symmetrized (round-off).
MatX CalcDelassus(const IslandRows& rows, const std::vector<MatX>& Y) {
  const int m = rows.size();
  MatX W = MatX::Zero(m, m);
  for (int b = 0; b < static_cast<int>(Y.size()); ++b) {
    const std::vector<int>& body_rows = rows.body_rows(b);
    for (size_t i = 0; i < body_rows.size(); ++i)
      rows[body_rows[i]].ForEachEntry([&](int on, int block, const Vec3& J) {
        if (on != b) return;
        const Eigen::RowVectorXd w_row = J.transpose() * Y[b].middleRows<3>(3 * block);
        for (size_t k = 0; k < body_rows.size(); ++k) W(body_rows[i], body_rows[k]) += w_row[k];
      });
  }
  return 0.5 * (W + W.transpose());
}
}  // namespace

FrozenIsland FreezeIsland(double h, const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                          const VecX& lambda, int prescribed) {
  TAUT_DEMAND(h > 0.0, "FreezeIsland: step h must be > 0 s, got ", h);
  TAUT_DEMAND(lambda.size() == rows.size(), "FreezeIsland: ", lambda.size(), " multipliers for ",
              rows.size(), " rows");
  TAUT_DEMAND(prescribed >= -1 && prescribed < static_cast<int>(bodies.size()),
              "FreezeIsland: prescribed body ", prescribed, " of an island of ", bodies.size());
  FrozenIsland island;
  for (int b = 0; b < static_cast<int>(bodies.size()); ++b)
    island.Y.push_back(b == prescribed
                           ? MatX::Zero(3 * bodies[b]->num_blocks(), rows.body_rows(b).size())
                           : SolveColumnsReadOnly(*bodies[b], b, rows));
  island.W = CalcDelassus(rows, island.Y);
  // q0 = C/h + J (v_ref - v), friction rows J v_ref, with v_ref = v* (a prescribed body: its
  // solved v), as SqpSolver::BuildQp at the solved iterate v.
  const int m = rows.size();
  island.q0.resize(m);
  for (int c = 0; c < m; ++c) {
    const ConstraintRow& row = rows[c];
    double jv_ref = 0.0, jv = 0.0;
    row.ForEachEntry([&](int body, int block, const Vec3& J) {
      const IslandBody& on = *bodies[body];
      jv_ref += J.dot((body == prescribed ? on.v() : on.v_star()).segment<3>(3 * block));
      jv += J.dot(on.v().segment<3>(3 * block));
    });
    island.q0[c] = row.friction_of > 0 ? jv_ref : row.C / h + jv_ref - jv;
  }
  rows.CalcPgsRows(island.rows);
  island.lambda0 = lambda;
  return island;
}

FrozenIslandLcp StackFrozenIslands(const std::vector<FrozenIsland>& islands,
                                   const std::vector<ToolJacobian>& tool_jacobians) {
  TAUT_DEMAND(islands.size() == tool_jacobians.size(), "StackFrozenIslands: ", islands.size(),
              " islands and ", tool_jacobians.size(), " tool Jacobians");
  int m = 0;
  for (const FrozenIsland& island : islands) m += static_cast<int>(island.rows.size());
  MatX W = MatX::Zero(m, m);
  VecX q0(m), lambda0(m);
  ToolJacobian J_t(m, 6);
  std::vector<PgsRow> rows;
  rows.reserve(m);
  int offset = 0;
  for (size_t i = 0; i < islands.size(); ++i) {
    const FrozenIsland& island = islands[i];
    const int n = static_cast<int>(island.rows.size());
    TAUT_DEMAND(tool_jacobians[i].rows() == n, "StackFrozenIslands: island ", i, " has ", n,
                " rows but its tool Jacobian ", tool_jacobians[i].rows());
    W.block(offset, offset, n, n) = island.W;
    q0.segment(offset, n) = island.q0;
    lambda0.segment(offset, n) = island.lambda0;
    J_t.middleRows(offset, n) = tool_jacobians[i];
    for (PgsRow row : island.rows) {
      if (row.normal >= 0) row.normal += offset;
      if (row.partner >= 0) row.partner += offset;
      rows.push_back(row);
    }
    offset += n;
  }
  return FrozenIslandLcp(std::move(W), std::move(q0), std::move(rows), std::move(lambda0),
                         std::move(J_t));
}

}  // namespace taut
