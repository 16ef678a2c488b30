// A deformable FEM body: runtime state and the linearized backward-Euler step (docs/math.md §5.1).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "plugin/deformable_body_settings.h"
#include "plugin/element_model.h"
#include "plugin/hex_lattice.h"
#include "plugin/implicit_system.h"
#include "plugin/node_kind.h"
#include "plugin/tet_mesh.h"

namespace taut {

// Runtime deformable body. Positions x and velocities v are 3N vectors (node-major xyz).
// One step h, split into stages so constraint solvers can act between them:
//   BeginStep:  A = M + h D + h^2 K,  b = M v0 + h f(x0)  (forces linearized at the step start,
//               D = alpha M + beta K), v* = A^-1 b (factoring A, or by CG on a kept
//               factor: settings.factor_reuse), set v = v*;
//   (constraints change v by A^-1 J^T lambda, using SolveSystem);
//   EndStep:    x = x0 + h v.
// Stage-boundary guards (after force assembly, after the unconstrained solve, at EndStep) throw
// SimulationError naming the body, the element or node and the stage when a force or velocity is
// not finite or a free node is faster than settings.max_speed. Before throwing they restore x and
// v to the step start and drop the step's external forces, so the body can be inspected or
// stepped again.
class DeformableBody {
 public:
  DeformableBody(std::unique_ptr<ElementModel> model, const DeformableBodySettings& settings);

  const std::string& name() const { return settings_.name; }
  const DeformableBodySettings& settings() const { return settings_; }
  const ElementModel& model() const { return *model_; }
  ElementModel& mutable_model() { return *model_; }
  // The rest mesh of a tet body (node positions [m]), null for other element models.
  const TetMesh* rest_tet_mesh() const { return model_->tet_mesh(); }
  // The rest lattice of a hex body (node positions [m]), null for other element models.
  const HexLattice* rest_hex_lattice() const { return model_->hex_lattice(); }
  // Rest volume of element e [m^3].
  double element_rest_volume(int e) const { return model_->element_rest_volume(e); }
  int num_nodes() const { return model_->num_nodes(); }
  int num_elements() const { return model_->num_elements(); }
  const VecX& x() const { return x_; }            // node positions (3N, node-major xyz) [m]
  const VecX& v() const { return v_; }            // node velocities (3N) [m/s]
  const VecX& x0() const { return x0_; }          // positions at the step start [m]
  const VecX& v_star() const { return v_star_; }  // unconstrained velocity of this step [m/s]
  const VecX& v0() const { return v0_; }          // velocity at the step start [m/s]
  const VecX& mass() const { return mass_; }      // lumped mass per node [kg]
  NodeKind node_kind(int i) const { return kinds_[i]; }
  // Node i's current position [m], world frame (x_i of x). Throws InputError naming the body and
  // the index for i outside [0, num_nodes()); nothing changes.
  Vec3 node_position(int i) const;
  // Node i's current velocity [m/s] (v_i of v: after a step the solved, constrained velocity).
  // Throws like node_position.
  Vec3 node_velocity(int i) const;
  // Node i's lumped mass m_i [kg] (mass()[i], > 0). Throws like node_position.
  double node_mass(int i) const;
  // The external force queued on node i for the next step by AddNodeForce [N] (zero after that
  // step has begun). Throws like node_position.
  Vec3 node_external_force(int i) const;
  const ImplicitSystem& system() const { return system_; }
  // The step's system, for the primal constraint solver's Newton matrix (between BeginStep and
  // EndStep).
  ImplicitSystem& mutable_system() { return system_; }

  // Sets positions/velocities (3N); throws InputError on size mismatch or non-finite values.
  void set_x(const VecX& x);
  void set_v(const VecX& v);
  // Velocity during a step (between BeginStep and EndStep), e.g. v* + A^-1 J^T lambda.
  VecX& mutable_v() { return v_; }

  // Fixes the listed nodes (v = 0). Throws InputError for an index out of range.
  void FixNodes(const std::vector<int>& nodes);
  // Fixes every node whose rest position satisfies pred; returns how many.
  int FixNodesWhere(const std::function<bool(const Vec3&)>& pred);
  // Makes the node kinematic and drives it to `target` by the end of each step.
  void SetKinematicTarget(int node, const Vec3& target);
  // Frees a fixed or kinematic node.
  void ReleaseNode(int node);
  // Adds an external force f [N] (world frame) on a node for the next step only: BeginStep adds
  // it to f(x0) in b = M v0 + h f(x0), so a free body without other forces gains momentum h f
  // (a node gets h f_i / m_i when every node is pushed with the same acceleration f_i / m_i), and
  // then clears it. In a DeformableWorld that step is the next fixed substep: with several
  // substeps per stepSimulation call only the first feels it (call again before each call, and
  // divide by the number of substeps for an impulse over the frame). Calls add up. No effect on
  // fixed or kinematic nodes. Throws InputError naming the body and the node for an index
  // outside [0, num_nodes()) or a non-finite force; nothing is queued then.
  void AddNodeForce(int node, const Vec3& force);

  // Threads that split this body's element loops in BeginStep (rotations, forces, the system's
  // assembly and factorization; null: the calling thread). Results are bitwise the same for any
  // runner.
  void set_element_loop_runner(ElementLoopRunner* runner) {
    model_->set_loop_runner(runner);
    system_.set_loop_runner(runner);
  }

  // Builds the system's sparsity pattern for the current node kinds and its symbolic
  // factorization (ordering, elimination tree, supernodes) now instead of in the next BeginStep,
  // which otherwise does it after a change of kinds (FixNodes, SetKinematicTarget, ReleaseNode,
  // a new body): call it once a body is set up, so that its first step costs what the others do
  // (the finger scene's new presses: 0.5-1 ms). No effect when nothing changed since the last
  // build; the steps' results are the same either way.
  void PrepareSystem();

  // Stage 2 of the world step: assemble, factor and solve the unconstrained velocity v*.
  // Throws InputError when h is not finite and > 0 or gravity is not finite, SimulationError
  // (state kept at the step start) on a non-finite force, a singular system or an exploding v*.
  void BeginStep(double h, const Vec3& gravity);
  // rhs <- A^-1 rhs on free DOFs, zero on fixed/kinematic DOFs (rhs is 3N). Factors this step's
  // A first if the unconstrained solve reused an earlier factor (ImplicitSystem::SolveStep);
  // throws SimulationError naming the body if A is not positive definite.
  void SolveSystem(Eigen::Ref<VecX> rhs);
  // Same for every column of a 3N x k matrix.
  void SolveSystemColumns(Eigen::Ref<MatX> rhs);
  // The halves of A^-1 (ImplicitSystem::HalfSolveColumns), factoring this step's A first like
  // SolveSystem: z = D^-1/2 L^-1 P rhs with rhs^T A^-1 rhs = z^T z, and out = A^-1 rhs c from
  // z c. Only on the SparseLdlt backend (HalfSolvesPay is false otherwise).
  bool HalfSolvesPay(int num_rows) const { return system_.HalfSolvesPay(num_rows); }
  void HalfSolveSystemColumns(const SparseColumns& rhs, MatX& z);
  void CompleteHalfSolve(const VecX& z, Eigen::Ref<VecX> out) const {
    system_.CompleteHalfSolve(z, out);
  }
  // rhs <- P^-1 rhs with the factor held (this step's A or a kept earlier one): an approximate
  // A^-1 for starting guesses that leaves the next step free to reuse the factor
  // (ImplicitSystem::SolveApproximately).
  void SolveSystemApproximately(Eigen::Ref<VecX> rhs) { system_.SolveApproximately(rhs, name()); }
  // PCG iterations of the last unconstrained solve on a kept factor; 0 when it factored A.
  int last_pcg_iterations() const { return last_pcg_iterations_; }
  // out = A v with this step's system matrix (free DOFs; 0 on fixed/kinematic DOFs).
  void ApplySystemMatrix(const VecX& v, VecX& out) const { system_.Multiply(v, out); }
  // Stage 7: x = x0 + h v. Throws SimulationError (keeping the step-start state) on NaN/Inf in
  // v or x, or a free node faster than settings.max_speed.
  void EndStep(double h);
  // Between BeginStep and EndStep: abandons the step (x, v back to the step start, this step's
  // external forces dropped), e.g. when another body of the world failed its step.
  void AbortStep();

  // Everything of the body the next step depends on besides its configuration (model, settings):
  // saved and restored by world snapshots (bullet_bridge/world_snapshot.h). The step's own
  // intermediates (x0, v0, v*, forces, A and its factor) are recomputed by BeginStep.
  struct State {
    VecX x, v;                            // positions [m] and velocities [m/s] (3N)
    VecX external;                        // forces queued by AddNodeForce [N] (3N)
    std::vector<NodeKind> kinds;          // free, fixed or kinematic, per node
    std::vector<Vec3> kinematic_targets;  // per node [m] (used by kinematic nodes)
    bool kinds_changed = true;            // the system is (re)built at the next BeginStep
    ImplicitSystem::NewtonState newton;   // the primal solver's Newton factor, reused later
  };
  State SaveState() const;
  // The same into `state`, reusing its storage: a state saved again and again into one object
  // allocates nothing after the first time (a real-time loop's take-back point).
  void SaveState(State& state) const;
  // Puts a saved state back, rebuilding the system when the node kinds differ. Between steps
  // only. Throws InputError naming the body, and changes nothing, when the state is of a body
  // with another number of nodes or its Newton state does not fit.
  void RestoreState(const State& state);

  // Elastic energy at the current x [J].
  double CalcElasticEnergy() const { return model_->CalcEnergy(x_); }
  // Kinetic energy 1/2 v^T M v [J].
  double CalcKineticEnergy() const;
  // Axis-aligned bounds of the current positions.
  void CalcBounds(Vec3& lo, Vec3& hi) const;

 private:
  // Throws InputError unless node is in [0, num_nodes()).
  void CheckNode(int node, const char* what) const;
  // RestoreState's system part: built for the saved kinds, with the saved Newton factor.
  void RestoreSystem(const State& state);
  // Force-assembly guard: names the node whose external force, or else the element whose elastic
  // force, is not finite.
  void CheckForces();
  // Velocity guard at `stage`: names the first node with a non-finite velocity, else the fastest
  // free node when it is faster than settings.max_speed.
  void CheckVelocities(const char* stage);
  // Restores x, v to the step start, drops the external forces and throws SimulationError
  // "body '<name>': <what> (stage: <stage>); state kept at step start".
  [[noreturn]] void FailStep(const std::string& what, const char* stage);

  std::unique_ptr<ElementModel> model_;
  DeformableBodySettings settings_;
  VecX x_, v_, x0_, v0_, v_star_, mass_;
  VecX force_;        // elastic + external + gravity at x0 (3N)
  VecX external_;     // user forces for the next step (3N)
  VecX kinematic_v_;  // prescribed velocities of kinematic nodes (3N, zero elsewhere)
  VecX scratch_;      // 3N
  std::vector<NodeKind> kinds_;
  std::vector<Vec3> kinematic_targets_;
  ImplicitSystem system_;
  int last_pcg_iterations_ = 0;  // of the last BeginStep (SolveStep)
  bool kinds_changed_ = true;
};

}  // namespace taut
