// A body of a constraint island as the SQP sees it (docs/math.md §5.2): velocity blocks, the step's
// system matrix A, the unconstrained velocity v*, and positions at a velocity.
#pragma once

#include <vector>

#include "plugin/common.h"
#include "plugin/sparse_columns.h"

namespace taut {

class DeformableBody;

// Deformable bodies have one 3-vector block per node (A = M + h D + h^2 K); rigid bodies have
// two, linear and angular velocity (A = diag(m I, I_world)). The SQP only needs A^-1 columns,
// A v products, v* and the current v.
class IslandBody {
 public:
  virtual ~IslandBody() = default;
  // Number of 3-vector velocity blocks.
  virtual int num_blocks() const = 0;
  // Unconstrained velocity of this step (3 * num_blocks).
  virtual const VecX& v_star() const = 0;
  // Velocity at the step start, the previous step's answer: a predictor of this step's
  // constrained velocity for the primal path's start (default: v*, no predictor).
  virtual const VecX& v_start() const { return v_star(); }
  // Current velocity (the SQP's iterate is written back here at the end of a solve).
  virtual const VecX& v() const = 0;
  virtual void set_v(const VecX& v) = 0;
  // columns <- A^-1 columns (zero on blocks that do not move freely).
  virtual void SolveSystemColumns(Eigen::Ref<MatX> columns) const = 0;
  // The halves of A^-1 for bodies with many blocks (docs/math.md §5.7): z = G rhs for a factor G
  // with A^-1 = G^T G (deformable: G = D^-1/2 L^-1 P of A's sparse factor), so the Delassus block
  // J A^-1 J^T = (G J^T)^T (G J^T) and A^-1 J^T c = G^T (G J^T c). Default: not supported.
  // HalfSolvesPay: true when the body has half solves and they are cheaper than full solves for
  // num_rows rows; the other two are called only then.
  virtual bool HalfSolvesPay(int num_rows) const {
    (void)num_rows;
    return false;
  }
  // rhs: sparse columns over the body's 3 num_blocks velocity entries.
  virtual void HalfSolveSystemColumns(const SparseColumns& rhs, MatX& z) const {
    (void)rhs;
    (void)z;
    throw InputError("island body: half solves are not supported");
  }
  // out = G^T z (3 * num_blocks; zero on blocks that do not move freely).
  virtual void CompleteHalfSolve(const VecX& z, VecX& out) const {
    (void)z;
    (void)out;
    throw InputError("island body: half solves are not supported");
  }
  // rhs <- an approximation of A^-1 rhs, for starting guesses (default: exact).
  virtual void SolveSystemApproximately(VecX& rhs) const { SolveSystemColumns(rhs); }
  // out = A v (zero on blocks that do not move freely).
  virtual void ApplySystemMatrix(const VecX& v, VecX& out) const = 0;
  // False for blocks pinned by the body itself (fixed or kinematic nodes).
  virtual bool is_free_block(int i) const = 0;
  // Positions after a step h at velocity v, for sources that read node positions (deformable:
  // x0 + h v). Bodies without nodes leave x empty.
  virtual void CalcPositions(double h, const VecX& v, VecX& x) const = 0;
  // The deformable body behind this island body, or null.
  virtual const DeformableBody* deformable() const { return nullptr; }

  // J^T A_diag^-1 J of a row entry J on block i: the entry's part of the diagonal Delassus
  // estimate w_c = sum_i J_i^T M_i^-1 J_i (lumped or rigid mass; 0 on blocks that do not move).
  virtual double CalcBlockMobility(int i, const Vec3& J) const = 0;

  // Primal path (constraints/primal_solver.h): the Newton matrix H = A + added blocks, factored
  // once per Newton iteration. H <- A.
  virtual void ResetNewtonMatrix() = 0;
  // True when H has an entry for the 3x3 block (i, j) (always for i == j).
  virtual bool IsInNewtonPattern(int i, int j) const = 0;
  // H(i, j) += block (blocks that do not move freely are dropped). Requires IsInNewtonPattern.
  virtual void AddNewtonBlock(int i, int j, const Mat3& block) = 0;
  // H(nodes of element e) += block (3k x 3k, the element's k nodes `nodes`, node-major): the
  // blocks of a row or curvature local to one element. By default one AddNewtonBlock per pair.
  virtual void AddNewtonElementBlock(int e, const int* nodes, const Eigen::Ref<const MatX>& block) {
    (void)e;
    const int k = static_cast<int>(block.rows() / 3);
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        AddNewtonBlock(nodes[a], nodes[b], block.block<3, 3>(3 * a, 3 * b));
  }
  // Factors H; throws SimulationError when it is not positive definite.
  virtual void FactorNewtonMatrix() = 0;
  // rhs <- H^-1 rhs (zero on blocks that do not move freely).
  virtual void SolveNewton(Eigen::Ref<VecX> rhs) const = 0;
  // columns <- H^-1 columns (default: one SolveNewton per column).
  virtual void SolveNewtonColumns(Eigen::Ref<MatX> columns) const {
    for (Eigen::Index i = 0; i < columns.cols(); ++i) SolveNewton(columns.col(i));
  }
  // out = H v (zero on blocks that do not move freely).
  virtual void ApplyNewtonMatrix(const VecX& v, VecX& out) const = 0;
  // The factor of an earlier H, if held, preconditions the Newton step instead of a new factor
  // (constraints/primal_solver.h, factor reuse): its cost in preconditioned CG iterations, or 0
  // when no factor is held or refactoring is cheap (rigid bodies: 6 x 6).
  virtual double CalcNewtonRefactorCost() const { return 0.0; }
};

// The bodies of an island with velocities and positions of one SQP iterate.
class IslandIterate {
 public:
  IslandIterate(double h, const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v,
                const std::vector<VecX>& x)
      : h_(h), bodies_(bodies), v_(v), x_(x) {}
  double h() const { return h_; }
  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  IslandBody& body(int b) const { return *bodies_[b]; }
  const VecX& v(int b) const { return v_[b]; }
  const VecX& x(int b) const { return x_[b]; }
  // Island index of a body; throws InputError when it is not in the island.
  int IndexOf(const IslandBody* body) const {
    for (size_t b = 0; b < bodies_.size(); ++b)
      if (bodies_[b] == body) return static_cast<int>(b);
    throw InputError("island: body is not part of this island");
  }
  int IndexOf(const DeformableBody* body) const {
    for (size_t b = 0; b < bodies_.size(); ++b)
      if (bodies_[b]->deformable() == body) return static_cast<int>(b);
    throw InputError("island: deformable body is not part of this island");
  }

 private:
  double h_;
  const std::vector<IslandBody*>& bodies_;
  const std::vector<VecX>& v_;
  const std::vector<VecX>& x_;
};

}  // namespace taut
