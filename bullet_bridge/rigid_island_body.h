// A dynamic Bullet rigid body as a body of a deformable island (two-way coupling,
// docs/architecture.md §4): velocity blocks (v, omega), A = diag(m I, I_world).
#pragma once

#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <Eigen/LU>

#include "constraints/island_body.h"

namespace taut {

// Block 0 is the linear velocity of the centre of mass, block 1 the angular velocity (world
// frame). Between BeginStep and EndStep the body's Bullet state is the step start; v* is Bullet's
// unconstrained velocity (external force and torque impulses, implicit gyroscopic term), and the
// solved v is written back at EndStep, before Bullet integrates the transform.
class RigidIslandBody final : public IslandBody {
 public:
  explicit RigidIslandBody(btRigidBody* body);

  // Saves the step-start transform and velocity and computes v* for a step of length h:
  //   v* = v + h F / m,  omega* = omega + h I^-1 tau (+ Bullet's implicit gyroscopic impulse).
  void BeginStep(double h);
  // Restores the step-start transform (undoing any pass of Bullet's own solver over the body)
  // and writes the solved velocity to the body.
  void EndStep();
  // Abandons the step: step-start transform and velocity back on the body.
  void AbortStep();

  int num_blocks() const override { return 2; }
  const VecX& v_star() const override { return v_star_; }
  const VecX& v() const override { return v_; }
  void set_v(const VecX& v) override { v_ = v; }
  // [dv; dw] = [lin_factor / m * f; I_world^-1 (ang_factor * tau)] per column.
  void SolveSystemColumns(Eigen::Ref<MatX> columns) const override;
  void ApplySystemMatrix(const VecX& v, VecX& out) const override;
  bool is_free_block(int /*i*/) const override { return true; }
  void CalcPositions(double /*h*/, const VecX& /*v*/, VecX& x) const override { x.resize(0); }
  double CalcBlockMobility(int i, const Vec3& J) const override;
  // Newton matrix H = A + B (B: the 6x6 blocks added), solved in mobility form
  // d = (I + A^+ B)^-1 A^+ rhs so locked axes (Bullet's linear/angular factors) stay at rest.
  void ResetNewtonMatrix() override { newton_added_.setZero(); }
  bool IsInNewtonPattern(int /*i*/, int /*j*/) const override { return true; }
  void AddNewtonBlock(int i, int j, const Mat3& block) override {
    newton_added_.block<3, 3>(3 * i, 3 * j) += block;
  }
  void FactorNewtonMatrix() override;
  void SolveNewton(Eigen::Ref<VecX> rhs) const override;
  void ApplyNewtonMatrix(const VecX& v, VecX& out) const override;

  // Transform after a step h at velocity v = [lin; ang] (Bullet's exponential-map integrator).
  btTransform PredictTransform(double h, const VecX& v) const;
  // Velocity of the material point p (world) at velocity v: lin + ang x (p - com).
  static Vec3 CalcPointVelocity(const VecX& v, const Vec3& p, const Vec3& com);
  btRigidBody* rigid() const { return body_; }
  const btTransform& start_transform() const { return start_; }

 private:
  btRigidBody* body_;
  btTransform start_;
  btVector3 start_linear_, start_angular_;
  VecX v_star_, v_;
  Mat3 inverse_inertia_;  // world frame, step start
  Mat3 inertia_;          // its pseudo-inverse
  Eigen::Matrix<double, 6, 6> newton_added_ = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> mobility_;                        // A^+ with the axis factors
  Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> newton_lu_;  // of I + A^+ B
};

}  // namespace taut
