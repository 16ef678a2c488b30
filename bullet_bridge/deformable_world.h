// Bullet dynamics world that also steps taut deformable bodies (docs/architecture.md §3).
#pragma once

#include <BulletCollision/CollisionDispatch/btEmptyCollisionAlgorithm.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>

#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "bullet_bridge/contact_report.h"
#include "bullet_bridge/deformable_collision_object.h"
#include "bullet_bridge/island_builder.h"
#include "bullet_bridge/island_thread_pool.h"
#include "bullet_bridge/joint_source.h"
#include "bullet_bridge/multibody_island_body.h"
#include "bullet_bridge/multibody_motor_source.h"
#include "bullet_bridge/node_attachment_source.h"
#include "bullet_bridge/rigid_contact_source.h"
#include "bullet_bridge/rigid_island_body.h"
#include "bullet_bridge/rigid_manifold_source.h"
#include "bullet_bridge/world_snapshot.h"
#include "constraints/deformable_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "constraints/energy_limit_source.h"
#include "constraints/island_solver.h"
#include "constraints/node_height_source.h"
#include "constraints/step_stats.h"
#include "constraints/strain_limit_source.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_mesh.h"

namespace taut {

// The constraint solver a Bullet world class is built with.
template <class BulletWorld>
struct WorldSolverOf {
  using type = btConstraintSolver;
};
template <>
struct WorldSolverOf<btMultiBodyDynamicsWorld> {
  using type = btMultiBodyConstraintSolver;
};

// Drop-in replacement for btDiscreteDynamicsWorld. Deformable bodies live in Bullet's broadphase
// as btCollisionObjects (AABBs refreshed every substep) and are stepped inside stepSimulation's
// fixed substeps together with the rigid bodies. Islands (docs/architecture.md §4) join each
// deformable body with the dynamic rigid bodies it touches or is attached to, and with the rigid
// bodies those touch through Bullet's contact manifolds; every island is one SQP whose QPs hold
// the limit rows, the deformable contact rows, the node attachments and Bullet's rigid-rigid
// contacts of the island, solved by one PGS. Rigid islands without deformables go to Bullet's
// own solver untouched; without deformable bodies every substep is exactly
// btDiscreteDynamicsWorld's.
//
// BulletWorld is btDiscreteDynamicsWorld (DeformableWorld) or btMultiBodyDynamicsWorld
// (DeformableMultiBodyWorld, below): there a btMultiBody whose link collider touches a deformable
// joins its island as a MultiBodyIslandBody with its joint motors as rows (two-way coupling,
// docs/architecture.md §4); without deformables every substep is exactly the Bullet world's.
template <class BulletWorld>
class DeformableWorldOf : public BulletWorld {
 public:
  // The constraint solver type BulletWorld takes (btMultiBodyConstraintSolver for multibodies).
  using Solver = typename WorldSolverOf<BulletWorld>::type;
  DeformableWorldOf(btDispatcher* dispatcher, btBroadphaseInterface* broadphase, Solver* solver,
                    btCollisionConfiguration* configuration);
  ~DeformableWorldOf() override;

  // Makes a co-rotational tet body from a mesh (validated; throws InputError) and adds it.
  // The world owns the body; the pointer stays valid until RemoveDeformableBody.
  DeformableBody* AddTetBody(const TetMesh& mesh, const DeformableBodySettings& settings);
  DeformableBody* AddTetBody(std::shared_ptr<const TetMesh> mesh,
                             const DeformableBodySettings& settings);
  // Makes a co-rotational hex body from a lattice (validated; throws InputError) and adds it;
  // `method` picks the element rotation (docs/math.md §4.4). Ownership as for AddTetBody.
  DeformableBody* AddHexBody(const HexLattice& lattice, const DeformableBodySettings& settings,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  DeformableBody* AddHexBody(std::shared_ptr<const HexLattice> lattice,
                             const DeformableBodySettings& settings,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  // The same, placed at `pose` (a rotation and a translation [m]): the nodes start at
  // pose * rest position, at rest (no elastic force; the elements are rotation invariant). The
  // rest mesh and everything given in its frame stay as they are: FixNodesWhere's rest positions,
  // strain-limit frames, SetContactSurface's surface. Throws InputError (before anything is
  // added) when the pose's basis is not a rotation.
  DeformableBody* AddTetBody(const TetMesh& mesh, const DeformableBodySettings& settings,
                             const btTransform& pose);
  DeformableBody* AddTetBody(std::shared_ptr<const TetMesh> mesh,
                             const DeformableBodySettings& settings, const btTransform& pose);
  DeformableBody* AddHexBody(const HexLattice& lattice, const DeformableBodySettings& settings,
                             const btTransform& pose,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  DeformableBody* AddHexBody(std::shared_ptr<const HexLattice> lattice,
                             const DeformableBodySettings& settings, const btTransform& pose,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  // Adds a body built elsewhere (any ElementModel).
  DeformableBody* AddDeformableBody(std::unique_ptr<DeformableBody> body);
  // Removes and destroys the body.
  void RemoveDeformableBody(DeformableBody* body);

  // Limits the principal stretches of every tet of `body` (paper A). Replaces earlier strain
  // limits of that body. Throws InputError for invalid settings or a body that is not a tet body.
  StrainLimitSource* SetStrainLimits(DeformableBody* body, const StrainLimitSettings& limits);
  // Limits the elastic energy of every element (tet or hex) of `body` to U_max (paper B:
  // C = 1 - U_e/U_max).
  // Replaces earlier energy limits of the body; throws InputError for invalid settings.
  EnergyLimitSource* SetEnergyLimits(DeformableBody* body, const EnergyLimitSettings& limits);
  // Keeps every free node of `body` at or above the world height z_min [m]: one unilateral row
  // C_i = z_i - z_min >= 0 per free node within the body's contact_margin of it (a floor no
  // Bullet object stands for; constraints/node_height_source.h). Replaces an earlier height limit
  // of the body; ClearLimits removes it. Throws InputError for a body not in this world or a
  // z_min that is not finite.
  NodeHeightSource* SetNodeHeightLimit(DeformableBody* body, double z_min);
  // Pins `nodes` of `body` to `rigid` at their current offsets in the rigid body's frame (a
  // bone in soft flesh). A static or kinematic rigid body drives the nodes kinematically; a
  // dynamic one is coupled both ways by bilateral rows in the island's solve (it feels the
  // flesh). The rigid body must be in this world. Throws InputError for a node out of range.
  void AttachNodesToRigidBody(DeformableBody* body, const std::vector<int>& nodes,
                              const btRigidBody* rigid);
  // Makes `surface` (a closed surface in the body's rest frame, e.g. the one a hex lattice was
  // voxelized from) the body's contact surface: it is embedded in the hex lattice or tet mesh,
  // and each of its vertices contacts rigid objects through the 8 nodes of its hex (trilinear
  // weights) or the 4 nodes of its tet (barycentric weights; EmbedSurfaceInTets). Without it a
  // body touches through its boundary nodes. Throws InputError for a body that is neither a hex
  // nor a tet body or a surface that cannot be embedded.
  void SetContactSurface(DeformableBody* body, const SurfaceMesh& surface);
  // Removes every constraint source (limits) of the body.
  void ClearLimits(DeformableBody* body);
  // Solver settings used by every constrained body; checked by ValidateSqpSettings at each
  // stepSimulation (InputError naming the field, nothing stepped).
  SqpSettings& mutable_solver_settings() { return solver_settings_; }
  const SqpSettings& solver_settings() const { return solver_settings_; }
  // Threads that step the deformables (default 1: everything on the caller's thread). With n > 1
  // a pool of n - 1 persistent worker threads and the caller run the bodies' unconstrained steps
  // (stage 2) and the independent islands' solves (stage 6) side by side; every result is bitwise
  // the one of 1 thread (each task writes only its own body or island; statistics are merged in
  // island order). Stays serial where sharing is not safe: in builds with CHOLMOD (its
  // factorization switches the process's OpenMP setting) and while a deformable touches a GImpact
  // shape (its triangle queries lock the shape). After a SimulationError the world is at the step
  // start either way, but with n > 1 the islands and bodies after the failing one have run their
  // part of the step: their warm starts are this step's. Throws InputError unless n >= 1.
  void SetThreadCount(int num_threads);
  int thread_count() const { return pool_ != nullptr ? pool_->num_threads() : 1; }

  int num_deformable_bodies() const { return static_cast<int>(bodies_.size()); }
  DeformableBody& deformable_body(int i) { return bodies_[i]->body(); }
  const DeformableBody& deformable_body(int i) const { return bodies_[i]->body(); }
  // Statistics of the last substep.
  const StepStats& last_step_stats() const { return stats_; }
  // btDiscreteDynamicsWorld::stepSimulation [s], keeping the totals of its substeps.
  int stepSimulation(btScalar time_step, int max_sub_steps = 1,
                     btScalar fixed_time_step = btScalar(1.) / btScalar(60.)) override;
  // Totals of the substeps of the last stepSimulation call (AddSubstepStats): times [ms] and
  // counts summed, violations and residuals the worst substep's, converged when every substep
  // converged, `substeps` their number (0 when the call only accumulated time; substeps without
  // deformable bodies count with zero figures). After a SimulationError: the substeps before it.
  const StepStats& last_call_stats() const { return call_stats_; }
  // Forces out (bullet_bridge/contact_report.h): the contacts, rigid wrenches and limit
  // multipliers the island solves of the LAST substep applied (a stepSimulation call of several
  // substeps keeps only its last one's; refilled by every substep, empty after a SimulationError,
  // after RemoveDeformableBody and in substeps without deformables). Impulses [N s], forces [N] =
  // impulse / h, torques [N m]; contact impulses act on the deformable, wrenches on the rigid
  // object (equal and opposite).
  const SubstepForces& last_substep_forces() const { return forces_; }
  // The last substep's contact points of `body` (impulses and force ON it, [N s] and [N]).
  // Throws InputError when the body is not in this world.
  std::vector<DeformableContactPoint> last_contacts(const DeformableBody* body) const;
  // The last substep's total wrench [N], [N m] on each rigid object from every deformable.
  const std::vector<RigidBodyWrench>& last_rigid_wrenches() const { return forces_.wrenches; }
  // The last substep's limit rows of `body` with their multipliers [N m s]. Throws InputError
  // when the body is not in this world.
  std::vector<LimitRowMultiplier> last_limit_multipliers(const DeformableBody* body) const;

  // The islands the last substep solved, as the forces out read them: their bodies (with this
  // substep's A, v* and solved v), the rows at the solved velocities and their multipliers. For
  // tools that re-solve them (bullet_bridge/haptic_force_loop.h). Empty before the first
  // substep, after a SimulationError, RemoveDeformableBody or RestoreSnapshot; valid until the
  // next of these or the next step.
  struct SolvedIsland {
    const std::vector<IslandBody*>* bodies = nullptr;
    const IslandRows* rows = nullptr;
    const VecX* multipliers = nullptr;
  };
  std::vector<SolvedIsland> last_solved_islands() const;
  // The nodes of `body` that AttachNodesToRigidBody pinned to the static or kinematic `rigid`
  // (kinematic nodes it drives), empty when none. Throws InputError when the body is not in this
  // world.
  std::vector<int> driven_nodes(const DeformableBody* body, const btRigidBody* rigid) const;

  // State snapshots (bullet_bridge/world_snapshot.h), between stepSimulation calls: everything
  // the next step depends on (deformables, warm starts, rigid bodies, joints, Bullet's contact
  // manifolds, the substep clock, the last step's statistics and forces), so a restored world
  // continues bit-identically to the one it was saved from (in a DeformableMultiBodyWorld the
  // multibodies' state is not part of it). A snapshot fits this world and any
  // world built the same way (same bodies, objects and joints in the same order).
  WorldSnapshot SaveSnapshot() const;
  // The same into `snapshot`, reusing its storage: saved again and again into one object (a
  // take-back point saved every step), it allocates nothing for the bodies' states after the
  // first time. Restoring it gives the same world as restoring a fresh SaveSnapshot().
  void SaveSnapshot(WorldSnapshot& snapshot) const;
  // Throws InputError saying what does not match, and changes nothing, when the snapshot is of a
  // world with other deformables (count, nodes, elements), collision objects (count, kind,
  // shape) or joints.
  void RestoreSnapshot(const WorldSnapshot& snapshot);

 protected:
  // One fixed substep; Bullet's sequence calls solveConstraints below between collision
  // detection and the integration of the rigid transforms.
  void internalSingleStepSimulation(btScalar h) override;
  // The deformable part of the substep, stages 2-7 (StepDeformables); Bullet's own solver for
  // the rigid-only islands runs inside it. Every body goes back to the step start on failure.
  void solveConstraints(btContactSolverInfo& info) override;

 private:
  // A body with its Bullet proxy, its constraint sources and its solver (warm starts).
  struct Entry {
    std::unique_ptr<DeformableCollisionObject> object;
    std::unique_ptr<DeformableIslandBody> island_body;
    std::vector<std::unique_ptr<BodyConstraintSource>> sources;  // limits
    std::unique_ptr<RigidContactSource> contacts;
    // Nodes pinned to static or kinematic rigid bodies (kinematic targets), with their offsets
    // in the rigid body's frame.
    struct Attachment {
      const btRigidBody* rigid;
      std::vector<int> nodes;
      std::vector<Vec3> local;
    };
    std::vector<Attachment> attachments;
    std::vector<std::unique_ptr<NodeAttachmentSource>> dynamic_attachments;
    std::vector<ContactPartner> partners;  // this step
    ContactSurface surface;                // contact points and triangles
    Vec3 swept_lo, swept_hi;               // bounds of this step's motion, grown by the margin
    IslandSolver solver;
    int island = -1;  // this step
    DeformableBody& body() { return object->body(); }
    btCollisionObject& collision_object() { return object->collision_object(); }
  };
  // Two deformables whose swept bounds overlap this step, with their contact source; or one
  // body with self_collision, both sides itself.
  struct DeformablePair {
    int first, second;  // entry indices, first < second (first == second: self-contact)
    DeformableContactSource* source;
  };
  // Stages of the substep (docs/architecture.md §3), in order; `begun` counts the bodies whose step
  // has begun, for the abort path of solveConstraints.
  void StepDeformables(double h, btContactSolverInfo& info, int& begun);
  // Stage 2: kinematic targets of attached nodes, then every body's unconstrained step (v*, x*).
  void BeginDeformableSteps(double h, int& begun);
  // Stage 3: each deformable's swept bounds, the rigid objects and the deformables they overlap.
  void FindContactPartners(double h);
  // Stage 3 for one body: rigid objects whose bounds overlap its swept bounds grown by `reach`.
  void FindRigidPartners(Entry& entry, double reach);
  // Stage 3 for deformable pairs: overlapping swept bounds, each pair with its contact source.
  void FindDeformablePairs();
  // Stage 4: union-find islands of deformables, their partners and attached rigid bodies, and
  // the rigid bodies joined to those by Bullet's manifolds and joints.
  void UniteIslands();
  // Stage 4: dynamic rigid bodies in deformable islands begin their step (before Bullet's solver
  // touches them) and join their island's bodies; contact partners get their island bodies.
  void CoupleRigidBodies(double h);
  // Stage 5: each island's row sources, with Bullet's manifolds and joints of its rigid bodies.
  void GatherRowSources(const btContactSolverInfo& info);
  // Stage 5: manifolds and joints touching a coupled rigid body, added to that body's island.
  void AddCoupledManifoldsAndJoints(const btContactSolverInfo& info);
  // Stage 6 for the rigid-only islands: Bullet's own solver.
  void SolveRigidIslandsWithBullet(btContactSolverInfo& info);
  // Stage 6 for the deformable islands: one SQP per island with rows (no rows: no LCP at all).
  void SolveIslands(double h);
  // True when this step's islands may be solved on several threads (see SetThreadCount).
  bool CanSolveIslandsInParallel() const;
  // Stage 7: x = x0 + h v; coupled rigid bodies get their solved velocity back.
  void EndSteps(double h);
  // Stage 8: forces out, each solved island's multipliers with their rows' metadata (forces_).
  void ReportForces();
  // Stage 8: the substep's totals from the stage timers (the islands' SQP stats are in already).
  void SumStageStats();
  // Drives nodes attached to static/kinematic rigid bodies to their current anchors.
  void UpdateKinematicAttachments();
  // Stage 6, after Bullet's solve: multibodies whose links touch a deformable begin their step
  // from Bullet's answer and join their island; contact partners get their island bodies.
  void CoupleMultiBodies(double h);
  // Stage 5 (multibody worlds): the joint motors of the multibodies in deformable islands become
  // island rows (MultiBodyMotorSource); Bullet's solver skips them this step (SuspendMotors).
  void GatherMultiBodyMotors();
  // Sets the max impulse of the gathered motors to 0 for Bullet's solve, and back.
  void SuspendMotors();
  void ResumeMotors();
  // The island body of a multibody (made on first use).
  MultiBodyIslandBody* FindMultiBodyIslandBody(btMultiBody* body);
  // The island body of the dynamic rigid body `object` when it is in a deformable island (then
  // `island` is set to that island), else null.
  RigidIslandBody* FindCoupledBody(const btCollisionObject& object, int& island);
  // The island body of a dynamic rigid body (made on first use).
  RigidIslandBody* FindRigidIslandBody(btRigidBody* rigid);
  // True when `body` is one of this world's deformables.
  bool HasBody(const DeformableBody* body) const;
  // The entry of a body; throws InputError when the body is not in this world.
  Entry& FindEntry(const DeformableBody* body);
  // Installs `source` on the body's entry, replacing any earlier source of the same type T.
  template <typename T>
  T* ReplaceSource(DeformableBody* body, std::unique_ptr<T> source);
  // The contact source of two deformables (friction and margin from their settings), or of one
  // body's self-contact when first and second are the same entry.
  std::unique_ptr<DeformableContactSource> MakePairContactSource(const Entry& first,
                                                                 const Entry& second,
                                                                 int source_id) const;
  // The stages of SaveSnapshot and RestoreSnapshot (bullet_bridge/world_snapshot.cc).
  struct Snapshots;

  std::vector<std::unique_ptr<Entry>> bodies_;
  std::unordered_map<const btCollisionObject*, std::unique_ptr<RigidIslandBody>> rigid_bodies_;
  // Contact sources of deformable pairs (kept across steps for warm starts), and this step's.
  struct PairContact {
    int source_id = -1;
    std::unique_ptr<DeformableContactSource> source;
  };
  std::map<std::pair<const Entry*, const Entry*>, PairContact> pair_contacts_;
  std::vector<DeformablePair> active_pairs_;
  IslandBuilder islands_;                  // this step's islands
  std::vector<RigidIslandBody*> coupled_;  // rigid bodies in deformable islands, this step
  std::unordered_map<const btMultiBody*, std::unique_ptr<MultiBodyIslandBody>> multibody_bodies_;
  std::vector<MultiBodyIslandBody*> coupled_multibodies_;  // multibodies in them, this step
  // Motor sources by island slot (made when an island first has motors), and this step's motors
  // with their max impulses while Bullet's solver runs.
  std::vector<std::unique_ptr<MultiBodyMotorSource>> motor_sources_;
  std::vector<std::pair<btMultiBodyJointMotor*, btScalar>> suspended_motors_;
  SqpSettings solver_settings_;
  std::unique_ptr<IslandThreadPool> pool_;  // null: one thread (SetThreadCount)
  // This step's islands with rows, each one's statistics and whether its solve returned; kept
  // across steps so that a step allocates nothing here.
  std::vector<int> solved_islands_;
  std::vector<StepStats> island_stats_;
  std::vector<char> island_done_;
  int next_source_id_ = 0;
  btEmptyAlgorithm::CreateFunc empty_algorithm_;
  StepStats stats_;
  StepStats call_stats_;  // totals of the last stepSimulation call
  SubstepForces forces_;  // forces out of the last substep

  // islands_ hold the last substep's solved islands (last_solved_islands).
  bool islands_solved_ = false;
};

// Instantiated in deformable_world.cc (and world_snapshot.cc for the snapshot members).
extern template class DeformableWorldOf<btDiscreteDynamicsWorld>;
extern template class DeformableWorldOf<btMultiBodyDynamicsWorld>;

// The world of rigid bodies and deformables.
using DeformableWorld = DeformableWorldOf<btDiscreteDynamicsWorld>;
// The world of rigid bodies, btMultiBodies and deformables.
using DeformableMultiBodyWorld = DeformableWorldOf<btMultiBodyDynamicsWorld>;

}  // namespace taut
