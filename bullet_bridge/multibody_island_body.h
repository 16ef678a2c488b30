// A Bullet btMultiBody as a body of a deformable island (two-way coupling of articulated robots,
// docs/architecture.md §4): its generalized velocity qdot in 3-vector blocks, A = its joint-space
// mass matrix M(q) at the step start.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBody.h>

#include <Eigen/LU>
#include <vector>

#include "bullet_bridge/multibody_jacobian.h"
#include "constraints/constraint_row.h"
#include "constraints/island_body.h"

namespace taut {

// qdot = [omega_base; v_base; joint rates] (n = 6 + dofs, Bullet's order) padded with zeros to
// 3 * ceil(n / 3) entries, in blocks of 3. The padding and, for a fixed base, the base entries
// have zero mobility (rows and columns of W = M^-1 are 0), as a rigid body's locked axes.
// Between BeginStep and EndStep the body's Bullet positions are the step start; v* is the
// velocity Bullet's multibody solver left (external forces, joint motors and limits, contacts
// with rigid objects), and the island's v is written back at EndStep, before Bullet integrates
// the joint positions.
class MultiBodyIslandBody final : public IslandBody {
 public:
  // Largest number of generalized velocities (6 + dofs) a row's side can hold.
  static constexpr int kMaxVelocities = 3 * kMaxRowNodes;
  // Throws InputError when the body is null or has more than kMaxVelocities - 6 dofs.
  explicit MultiBodyIslandBody(btMultiBody* body);

  // Reads v* and computes W = M^-1 (columns by btMultiBody::calcAccelerationDeltasMultiDof,
  // which needs Bullet's articulated-body pass of this step) and M = W^+.
  void BeginStep(double h);
  // Writes the solved velocity to the body.
  void EndStep();
  // Abandons the step: the velocity read at BeginStep back on the body.
  void AbortStep();

  int num_blocks() const override { return num_blocks_; }
  const VecX& v_star() const override { return v_star_; }
  const VecX& v() const override { return v_; }
  void set_v(const VecX& v) override { v_ = v; }
  void SolveSystemColumns(Eigen::Ref<MatX> columns) const override { columns = W_ * columns; }
  void ApplySystemMatrix(const VecX& v, VecX& out) const override { out = M_ * v; }
  bool is_free_block(int /*i*/) const override { return true; }
  void CalcPositions(double /*h*/, const VecX& /*v*/, VecX& x) const override { x.resize(0); }
  // J^T W_ii J over block i.
  double CalcBlockMobility(int i, const Vec3& J) const override {
    return J.dot(W_.block<3, 3>(3 * i, 3 * i) * J);
  }
  // Newton matrix H = M + B in mobility form d = (I + W B)^-1 W rhs (as RigidIslandBody).
  void ResetNewtonMatrix() override { newton_added_.setZero(); }
  bool IsInNewtonPattern(int /*i*/, int /*j*/) const override { return true; }
  void AddNewtonBlock(int i, int j, const Mat3& block) override {
    newton_added_.block<3, 3>(3 * i, 3 * j) += block;
  }
  void FactorNewtonMatrix() override;
  void SolveNewton(Eigen::Ref<VecX> rhs) const override;
  void ApplyNewtonMatrix(const VecX& v, VecX& out) const override;

  // Row entries (blocks and their 3-vectors, at most kMaxRowNodes) of sign * j, the Jacobian of
  // d . (velocity of `link`'s material point at p); blocks whose entries are all 0 (a fixed
  // base's) are left out.
  // Returns the number of entries.
  int FillPointRowEntries(int link, const Vec3& p, const Vec3& d, double sign, int* blocks,
                          Vec3* J) const;
  // World transform of `link`'s collider after a step h at velocity v: its step-start transform
  // moved by the link's angular velocity and the velocity of its origin (first order in h).
  btTransform PredictColliderTransform(int link, double h, const VecX& v) const;
  btMultiBody* multibody() const { return body_; }

 private:
  // Sizes of the vectors and matrices for the body's dofs now; throws InputError beyond
  // kMaxVelocities.
  void FitSizes();
  // W = M^-1 by columns (zero rows and columns for the padding and a fixed base).
  void CalcMobility();

  btMultiBody* body_;
  int num_velocities_ = -1;  // 6 + dofs
  int num_blocks_ = 0;
  VecX v_star_, v_;
  MatX W_, M_;
  MatX newton_added_;
  Eigen::PartialPivLU<MatX> newton_lu_;
  // Per link (index link + 1): the collider's step-start transform and frame Jacobian there.
  std::vector<btTransform> collider_start_;
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic>> collider_jacobian_;
  mutable MultiBodyScratch scratch_;
};

}  // namespace taut
