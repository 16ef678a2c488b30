// The sparse system A = c_M M + c_K K of one body on its free DOFs, with a fixed pattern.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "plugin/cholmod_cholesky.h"
#include "plugin/deformable_body_settings.h"
#include "plugin/element_model.h"
#include "plugin/node_kind.h"
#include "plugin/sparse_ldlt.h"

namespace taut {

// Which sparse factorization an ImplicitSystem uses.
enum class LinearSolverKind {
  kAuto,        // SparseLdlt; with TAUT_WITH_CHOLMOD, CHOLMOD from kCholmodMinFreeDofs free DOFs
  kSparseLdlt,  // always the allocation-free scalar LDL^T (plugin/sparse_ldlt.h)
  kCholmod,     // always CHOLMOD's supernodal LL^T (plugin/cholmod_cholesky.h); InputError at
                // Build in a build without CHOLMOD (IsCholmodAvailable() false, the default)
};

// Symbolic structure built once per body (and again only when nodes are fixed or released):
// the free-DOF numbering, the full symmetric CSC pattern of A, the element -> value index map
// and the factorization's analysis. Each step then writes values through the map (no
// setFromTriplets, no allocation) and refactors numerically.
//
// Backend (kAuto): SparseLdlt for every body unless the build links CHOLMOD (CMake option
// TAUT_WITH_CHOLMOD, off by default because CHOLMOD's Supernodal module is GPL-2+); then by size:
// the scalar up-looking SparseLdlt never touches the heap after Build, but
// its flops grow like n^2 on 3D meshes and run one scalar at a time; CHOLMOD's supernodal
// factorization runs them as dense BLAS-3 blocks but allocates inside every Factor. Factor + solve,
// CHOLMOD vs SparseLdlt (bench/factorization_bench.cc, serial OpenBLAS): break-even near 400 free
// DOFs on tet beams (250 on hex balls), 1.3x at 500, 2x at 900, 5.6x at 1.9k (armadillo-sized
// hexes), 6.4x at 12.6k, 40x at 58k. So a step of a body with fewer than kCholmodMinFreeDofs free
// DOFs makes no heap allocation, and a larger body's step allocates a few buffers inside Factor
// (none in the solves).
class ImplicitSystem {
 public:
  // Free-DOF count from which kAuto picks CHOLMOD: the measured crossover of factor + solve
  // (bench/factorization_bench.cc), rounded up; smaller bodies keep allocation-free steps.
  static constexpr int kCholmodMinFreeDofs = 500;

  // Chooses the backend for the next Build (default kAuto).
  void set_linear_solver(LinearSolverKind kind) { requested_solver_ = kind; }
  // Builds the pattern for the model's connectivity with the given node kinds.
  void Build(const ElementModel& model, const std::vector<NodeKind>& kinds);
  // A = c_M diag(mass) + c_K K(rotations of the model's last update), on free DOFs.
  void Assemble(const ElementModel& model, const VecX& mass, double c_M, double c_K);
  // Numeric factorization; throws SimulationError naming `body` if A is not positive definite.
  void Factor(const std::string& body);
  // The unconstrained solve of a step, rhs (3N) <- A^-1 rhs, with factor reuse (docs/solver.md,
  // "Factor reuse in the unconstrained step"): when `reuse` allows it and a factor of an earlier
  // step's A is held whose refactor costs at least reuse.min_refactor_cost PCG iterations, CG on
  // this A preconditioned by that factor runs to a relative residual of reuse.pcg_tolerance,
  // within that cost; else (also when the last step's constraint solve needed A^-1, see
  // EnsureCurrentFactor) A is factored and solved directly. Returns the PCG iterations, 0 for
  // the direct solve. Throws SimulationError naming `body` if A is not positive definite.
  int SolveStep(Eigen::Ref<VecX> rhs, const std::string& body, const FactorReuseSettings& reuse);
  // Factors A if the held factor is an earlier step's (SolveStep kept it), so that Solve and
  // SolveColumns apply this step's A^-1. Throws SimulationError like Factor.
  void EnsureCurrentFactor(const std::string& body);
  // True when the held factor is the one of this step's A (Solve and SolveColumns are exact).
  bool factor_is_current() const { return factor_current_; }
  // True when A is factored by SparseLdlt's supernodal kernel (large bodies, default backend).
  bool uses_supernodal_factor() const { return !use_cholmod_ && ldlt_.supernodal(); }
  // rhs (3N) <- A^-1 rhs on free DOFs; constrained DOFs set to 0. Requires factor_is_current().
  void Solve(Eigen::Ref<VecX> rhs) const;
  // Same for each column of rhs (3N x k).
  void SolveColumns(Eigen::Ref<MatX> rhs) const;
  // The halves of A^-1 (SparseLdlt::HalfSolveColumns; the SparseLdlt backend only, see
  // supports_half_solve): z (num_free x k) = D^-1/2 L^-1 P rhs on free DOFs for the k sparse
  // columns rhs (indices are DOFs 3 node + axis; entries on constrained DOFs are dropped), so
  // that rhs^T A^-1 rhs = z^T z; CompleteHalfSolve: out (3N) = A^-1 rhs c from z c (constrained
  // DOFs 0). Require factor_is_current().
  bool supports_half_solve() const { return !use_cholmod_; }
  // True when half solves are cheaper than full ones for a Delassus block of num_rows rows:
  // a column's full solve adds the backward pass (2 nnz(L) multiply-adds), a half-solved column
  // adds its products in W = Z^T Z (at most num_free num_rows / 2), so half solves pay while
  // num_rows num_free < 4 nnz(L). Measured (taut-demo, Σ ms_solve): the armadillo's bodies (90
  // contact rows, 2,361 free DOFs) 2,113 -> 1,323 ms with half solves; the gripper's finger pads
  // (limit rows solved afresh in every SQP iteration) 1,436 -> 1,709 ms.
  bool HalfSolvesPay(int num_rows) const;
  void HalfSolveColumns(const SparseColumns& rhs, MatX& z) const;
  void CompleteHalfSolve(const VecX& z, Eigen::Ref<VecX> out) const;
  // rhs (3N) <- P^-1 rhs with the held factor P, this step's A or an earlier step's kept one: an
  // approximate A^-1 for starting guesses, which does not make the next step factor A (unlike
  // EnsureCurrentFactor). Factors A when no factor is held. Throws SimulationError like Factor.
  void SolveApproximately(Eigen::Ref<VecX> rhs, const std::string& body);

  // out (3N) = A v on free DOFs (v read on free DOFs only), 0 on constrained DOFs.
  void Multiply(const VecX& v, VecX& out) const;

  int num_free_dofs() const { return static_cast<int>(free_to_dof_.size()); }
  // Free index of a DOF (3 node + axis), or -1 when fixed or kinematic.
  int free_index(int dof) const { return dof_to_free_[dof]; }
  const Eigen::SparseMatrix<double>& matrix() const { return A_; }
  // True when the last Build chose CHOLMOD.
  bool uses_cholmod() const { return use_cholmod_; }

  // Newton matrix of the primal constraint solver: H = A + blocks added by AddNewtonBlock, on A's
  // pattern, with its own numeric factor (the symbolic analysis is made on first use after Build).
  // H <- A (this step's values).
  void ResetNewtonMatrix();
  // True when the 3x3 block between nodes a and b lies in A's pattern (or touches a node that is
  // not free, whose DOFs are not in the system).
  bool IsInPattern(int a, int b) const;
  // H(a, b) += block on the free DOFs of nodes a and b; a block touching a fixed or kinematic
  // node is dropped. Requires IsInPattern(a, b).
  void AddNewtonBlock(int a, int b, const Mat3& block);
  // H(nodes of element e) += block (3k x 3k over the element's k nodes, node-major) through the
  // element's value map; entries on fixed or kinematic nodes are dropped.
  void AddNewtonElementBlock(int e, const Eigen::Ref<const MatX>& block);
  // Numeric factorization of H; throws SimulationError naming `body` if H is not positive definite.
  void FactorNewtonMatrix(const std::string& body);
  // rhs (3N) <- H^-1 rhs on free DOFs; constrained DOFs set to 0.
  void SolveNewton(Eigen::Ref<VecX> rhs) const;
  // rhs <- H^-1 rhs, column by column in blocks (SparseLdlt::SolveColumns).
  void SolveNewtonColumns(Eigen::Ref<MatX> rhs) const;
  // out (3N) = H v on free DOFs, 0 on constrained DOFs.
  void MultiplyNewton(const VecX& v, VecX& out) const;
  // True when a factor of some earlier H (this pattern) is held: usable as a preconditioner.
  bool HasNewtonFactor() const;
  // Cost of factoring H in units of one preconditioned CG iteration with the held factor (two
  // triangular solves, 4 nnz(L), plus the product with A, 2 nnz(A)); 0 with CHOLMOD (its factor
  // is not reused) or before the first factor.
  double CalcNewtonRefactorCost() const;

  // The part of the system that outlives a step: the Newton matrix H and its SparseLdlt factor,
  // which the primal solver's next steps reuse as a preconditioner (factor reuse), and A's factor,
  // which the next unconstrained solves may reuse (SolveStep). Saved by world snapshots
  // (bullet_bridge/world_snapshot.h) so a restored body continues bit-identically. With CHOLMOD
  // nothing is kept (its factors are never reused): `analyzed` stays false.
  struct NewtonState {
    bool analyzed = false;  // H's pattern and symbolic analysis are set up
    Eigen::SparseMatrix<double> H;
    SparseLdlt factor;
    SparseLdlt system_factor;   // A's factor of the last step that factored A
    bool exact_solves = false;  // the last step's constraint solve needed this step's A^-1
  };
  NewtonState SaveNewtonState() const;

  // Threads for the factorizations (null: the calling thread): a large SparseLdlt factor splits
  // over two of them, bitwise the same (SupernodalCholesky::Factorize). Not part of the state.
  void set_loop_runner(ElementLoopRunner* runner) { loop_runner_ = runner; }
  // The SparseLdlt factor of A (empty when the backend is CHOLMOD).
  const SparseLdlt& sparse_ldlt() const { return ldlt_; }
  // The same into `state`, reusing its storage (no allocation once it has held a state of this
  // system). H and factor are left as they were when `analyzed` comes out false: unused then.
  void SaveNewtonState(NewtonState& state) const;
  // Puts a saved state back (CHOLMOD: no-op). The system must be built with the node kinds of the
  // saved one; throws InputError, changing nothing, when H's size or pattern size differ.
  void RestoreNewtonState(const NewtonState& state);

 private:
  std::vector<int> dof_to_free_;   // (3N) free index or -1
  std::vector<int> free_to_dof_;   // (num_free)
  std::vector<int> diagonal_;      // (num_free) value index of A(i,i)
  std::vector<int> element_map_;   // (num_elements x k^2 x 9) value index or -1
  int nodes_per_element_ = 0;      // k
  Eigen::SparseMatrix<double> A_;  // full symmetric, free DOFs
  LinearSolverKind requested_solver_ = LinearSolverKind::kAuto;
  bool use_cholmod_ = false;
  SparseLdlt ldlt_;              // the factor when !use_cholmod_
  CholmodCholesky cholmod_;      // the factor when use_cholmod_
  bool factor_current_ = false;  // the factor is of A's values (not an earlier step's A)
  ElementLoopRunner* loop_runner_ = nullptr;  // set_loop_runner
  bool exact_solves_ = false;  // EnsureCurrentFactor was called since the last SolveStep
  // Cost of factoring A in PCG iterations with the held factor (4 nnz(L) + 2 nnz(A) flops each),
  // 0 without a SparseLdlt factor.
  double CalcRefactorCost(const SparseLdlt& factor) const;
  // x = A^-1 b on free DOFs by CG preconditioned with the held (earlier) factor of A, at most
  // max_iterations preconditioner applications, to ||b - A x|| <= tolerance ||b||. Returns the
  // applications used, or -1 when the budget ran out (x then unusable).
  int SolveByKeptFactor(VecX& b_then_x, double tolerance, int max_iterations) const;
  mutable VecX cg_r_, cg_z_, cg_p_, cg_ap_, cg_x_;  // PCG work vectors (num_free)
  // Numeric factorization of M (A or H, same pattern) into the chosen backend's factor; false
  // when M is not positive definite.
  bool FactorWith(const Eigen::SparseMatrix<double>& M, SparseLdlt& ldlt,
                  CholmodCholesky& cholmod) const;
  // rhs (3N) <- M^-1 rhs on free DOFs with a factor of FactorWith; constrained DOFs set to 0.
  void SolveWith(const SparseLdlt& ldlt, const CholmodCholesky& cholmod,
                 Eigen::Ref<VecX> rhs) const;
  // The same for the columns of rhs (3N x k).
  void SolveColumnsWith(const SparseLdlt& ldlt, const CholmodCholesky& cholmod,
                        Eigen::Ref<MatX> rhs) const;
  // out (3N) = M v on free DOFs, 0 on constrained DOFs.
  void MultiplyWith(const Eigen::SparseMatrix<double>& M, const VecX& v, VecX& out) const;
  // Value index of the first of the three rows of node a in column (free DOF) col, or -1.
  int FindBlockRow(int a, int col) const;
  // Newton matrix (primal solver): A's pattern, own values and factor.
  Eigen::SparseMatrix<double> H_;
  bool newton_analyzed_ = false;
  SparseLdlt newton_ldlt_;
  CholmodCholesky newton_cholmod_;
  mutable VecX rhs_free_;
  mutable SparseColumns sparse_free_;  // HalfSolveColumns: rhs on free DOFs
  mutable MatX columns_free_;
  mutable VecX product_free_;
};

}  // namespace taut
