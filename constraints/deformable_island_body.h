// A deformable body as an island body (one velocity block per node).
#pragma once

#include "constraints/island_body.h"
#include "plugin/deformable_body.h"

namespace taut {

// Adapter: A, v* and v are the body's own (between BeginStep and EndStep).
class DeformableIslandBody final : public IslandBody {
 public:
  explicit DeformableIslandBody(DeformableBody& body) : body_(&body) {}
  int num_blocks() const override { return body_->num_nodes(); }
  const VecX& v_star() const override { return body_->v_star(); }
  const VecX& v_start() const override { return body_->v0(); }
  const VecX& v() const override { return body_->v(); }
  void set_v(const VecX& v) override { body_->mutable_v() = v; }
  void SolveSystemColumns(Eigen::Ref<MatX> columns) const override {
    body_->SolveSystemColumns(columns);
  }
  bool HalfSolvesPay(int num_rows) const override { return body_->HalfSolvesPay(num_rows); }
  void HalfSolveSystemColumns(const SparseColumns& rhs, MatX& z) const override {
    body_->HalfSolveSystemColumns(rhs, z);
  }
  void CompleteHalfSolve(const VecX& z, VecX& out) const override {
    out.resize(3 * num_blocks());
    body_->CompleteHalfSolve(z, out);
  }
  void SolveSystemApproximately(VecX& rhs) const override { body_->SolveSystemApproximately(rhs); }
  void ApplySystemMatrix(const VecX& v, VecX& out) const override {
    body_->ApplySystemMatrix(v, out);
  }
  bool is_free_block(int i) const override { return body_->node_kind(i) == NodeKind::kFree; }
  // x = x0 + h v (docs/math.md §5.1: positions of the backward-Euler step).
  void CalcPositions(double h, const VecX& v, VecX& x) const override { x = body_->x0() + h * v; }
  const DeformableBody* deformable() const override { return body_; }
  double CalcBlockMobility(int i, const Vec3& J) const override {
    return is_free_block(i) ? J.squaredNorm() / body_->mass()[i] : 0.0;
  }
  void ResetNewtonMatrix() override { body_->mutable_system().ResetNewtonMatrix(); }
  bool IsInNewtonPattern(int i, int j) const override { return body_->system().IsInPattern(i, j); }
  void AddNewtonBlock(int i, int j, const Mat3& block) override {
    body_->mutable_system().AddNewtonBlock(i, j, block);
  }
  void AddNewtonElementBlock(int e, const int* /*nodes*/,
                             const Eigen::Ref<const MatX>& block) override {
    body_->mutable_system().AddNewtonElementBlock(e, block);
  }
  void FactorNewtonMatrix() override { body_->mutable_system().FactorNewtonMatrix(body_->name()); }
  void SolveNewton(Eigen::Ref<VecX> rhs) const override { body_->system().SolveNewton(rhs); }
  void SolveNewtonColumns(Eigen::Ref<MatX> columns) const override {
    body_->system().SolveNewtonColumns(columns);
  }
  double CalcNewtonRefactorCost() const override {
    return body_->system().CalcNewtonRefactorCost();
  }
  void ApplyNewtonMatrix(const VecX& v, VecX& out) const override {
    body_->system().MultiplyNewton(v, out);
  }
  DeformableBody& body() { return *body_; }

 private:
  DeformableBody* body_;
};

}  // namespace taut
