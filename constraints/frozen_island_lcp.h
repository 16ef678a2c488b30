// The contact and limit LCP of solved islands, frozen after a step and re-solved against a tool's
// motion (the haptic loop, docs/haptics.md; the approach of SOFA's LCPForceFeedback).
#pragma once

#include <vector>

#include "constraints/island_body.h"
#include "constraints/island_rows.h"
#include "constraints/pgs_solver.h"
#include "plugin/deformable_body.h"

namespace taut {

// A tool's twist: linear part [m/s] on top, angular part [rad/s] below, world frame.
using ToolTwist = Eigen::Matrix<double, 6, 1>;
// (m x 6) the row velocities' derivative dw/du with respect to the tool's twist u.
using ToolJacobian = Eigen::Matrix<double, Eigen::Dynamic, 6>;

// The LCP of one or more solved islands as it stood at the end of a step, with the tool's twist
// change u as its only input (docs/haptics.md eq. H1-H3):
//   w(lambda, u) = W lambda + q0 + J_t u,                                          (H1)
//   0 <= lambda_n  complementary to  w_n >= 0;  ||lambda_t|| <= mu lambda_n;  bilateral in [lo,
//   hi],
// with W = J A^-1 J^T, q0 = C/h + J (v* - v) (friction rows: J v*) and J of the step's last
// rows, A the step's system matrix. The tool receives the rows' generalized impulse
//   p = J_t^T lambda,                                                              (H2)
// by reciprocity (J_t = dw/du: the same matrix moves the rows and carries their impulse back).
// At u = 0 the step's own multipliers lambda0 solve (H1) to the step's tolerance, so p(0) is the
// step's impulse on the tool (H3). Solve touches nothing but this object: a haptic thread may own
// it while the world steps on.
class FrozenIslandLcp {
 public:
  FrozenIslandLcp() = default;
  // Takes the frozen problem. Throws InputError when the sizes disagree, W is not square,
  // symmetric and finite, or a row's data is invalid (ValidateLcpProblem).
  FrozenIslandLcp(MatX W, VecX q0, std::vector<PgsRow> rows, VecX lambda0, ToolJacobian J_t);

  // What one Solve did.
  struct Result {
    ToolTwist impulse = ToolTwist::Zero();  // p = J_t^T lambda [N s; N m s] (H2)
    PgsStats pgs;                           // sweeps, last change, natural-map residual
  };
  // lambda for the tool twist change u by one PGS, warm-started from the last Solve's lambda
  // (lambda0 before the first); returns p. Allocates no heap memory.
  Result Solve(const ToolTwist& u, const PgsSettings& settings);
  // The next Solve starts from lambda0 again.
  void ResetWarmStart() { lambda_ = lambda0_; }

  int size() const { return static_cast<int>(rows_.size()); }
  const MatX& W() const { return W_; }
  const VecX& q0() const { return q0_; }
  const std::vector<PgsRow>& rows() const { return rows_; }
  const ToolJacobian& tool_jacobian() const { return J_t_; }
  const VecX& lambda0() const { return lambda0_; }
  // The last Solve's multipliers (lambda0 before the first).
  const VecX& lambda() const { return lambda_; }

 private:
  MatX W_;
  VecX q0_, lambda0_;
  std::vector<PgsRow> rows_;
  ToolJacobian J_t_;
  VecX q_, lambda_, w_;  // this Solve's q = q0 + J_t u, multipliers and w = W lambda + q
};

// The frozen QP data of one solved island: W = J A^-1 J^T, q0, the PGS rows and lambda0 (H1),
// and per body b the columns Y_b = A_b^-1 J_b^T (3 num_blocks x rows of b, body_rows order).
struct FrozenIsland {
  MatX W;
  VecX q0;
  std::vector<PgsRow> rows;
  VecX lambda0;
  std::vector<MatX> Y;
};

// Freezes an island as its solve left it: `rows` and `lambda` (IslandSolver::last_rows() and
// last_multipliers()), the bodies with this step's A, v* and solved v. Changes no body: a
// deformable's A^-1 comes from its held factor, which must be this step's (true after a dual
// solve, which used it); throws InputError naming the body otherwise (factor_reuse kept an
// earlier factor and nothing factored A since). Island body `prescribed` (or -1: none) is a
// tool whose velocity is the user's, not the solve's: it leaves W (no mobility) and enters q0
// with its solved velocity, its rows moved by J_t instead (AddPrescribedBodyToolJacobian).
FrozenIsland FreezeIsland(double h, const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                          const VecX& lambda, int prescribed = -1);

// Stacks islands into one LCP: W block-diagonal, rows and J_t blocks in order (row indices of
// friction rows shifted to the stacked numbering).
FrozenIslandLcp StackFrozenIslands(const std::vector<FrozenIsland>& islands,
                                   const std::vector<ToolJacobian>& tool_jacobians);

}  // namespace taut
