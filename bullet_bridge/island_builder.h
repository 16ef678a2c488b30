// Islands of one world substep (docs/architecture.md §3, stage 4): each deformable body united with
// the dynamic rigid bodies it touches or is attached to, and through Bullet's contact manifolds
// and joints with the rigid bodies those touch.
#pragma once

#include <BulletDynamics/Dynamics/btDynamicsWorld.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>

#include <array>
#include <memory>
#include <vector>

#include "bullet_bridge/joint_source.h"
#include "bullet_bridge/rigid_manifold_source.h"
#include "constraints/island_body.h"
#include "constraints/union_find.h"

namespace taut {

// One island of a substep: its bodies (deformables first), its row sources, and the Bullet
// manifolds and joints of its rigid bodies.
struct Island {
  std::vector<IslandBody*> bodies;
  std::vector<ConstraintSource*> sources;
  std::unique_ptr<RigidManifoldSource> manifolds;
  std::unique_ptr<JointSource> joints;
  int first_deformable = -1;  // its solver keeps the warm starts
};

// Union-find over the deformable bodies (indices 0..n-1, in the world's order), Bullet's
// dynamic rigid bodies (n..n+m-1, in world array order) and the btMultiBodies with a movable
// link collider (n+m..n+m+k-1, in order of their first collider in the world array). The smaller
// representative wins, so the root of a set with deformables is its first deformable; sets without
// one are rigid-only islands, Bullet's alone. Storage is kept across steps: once the capacities
// suffice, a step allocates nothing here.
class IslandBuilder {
 public:
  // True for a rigid body Bullet moves (not static, not kinematic, not a deformable's proxy).
  static bool IsDynamicRigidBody(const btCollisionObject& object);

  // Starts a step: numbers the dynamic rigid bodies among `objects` after `num_deformables`
  // deformable bodies, every body its own set.
  void Reset(int num_deformables, const btCollisionObjectArray& objects);
  // Union-find index of a collision object: >= num_deformables for dynamic rigid bodies, else -1.
  int DynamicIndex(const btCollisionObject& object) const;
  // Union-find index of the multibody whose movable link collider `object` is, else -1.
  int MultiBodyIndex(const btCollisionObject& object) const;
  // Joins the sets of union-find indices a and b.
  void Unite(int a, int b) { union_find_.Unite(a, b); }
  // Joins dynamic rigid bodies that touch (Bullet manifolds with points).
  void UniteTouchingRigidBodies(btDispatcher& dispatcher);
  // Joins dynamic rigid bodies connected by enabled Bullet joints.
  void UniteJointedRigidBodies(const btDynamicsWorld& world);
  // Makes one island per set holding a deformable, emptied for this step; `next_source_id`
  // numbers the manifold and joint sources of islands made for the first time.
  void MakeDeformableIslands(int& next_source_id);

  // Source ids of the manifold and joint sources of every island slot made so far (slots are
  // reused by later steps, so their ids are part of the world's state: world snapshots).
  std::vector<std::array<int, 2>> SaveSourceIds() const;
  // Makes the slots those of SaveSourceIds (recreating a source whose id differs) and forgets
  // this step's islands (num_islands() = 0 until the next MakeDeformableIslands).
  void RestoreSourceIds(const std::vector<std::array<int, 2>>& ids);

  int num_islands() const { return num_islands_; }
  Island& island(int i) { return islands_[i]; }
  const Island& island(int i) const { return islands_[i]; }
  // Island of deformable body d (after MakeDeformableIslands).
  int island_of_deformable(int d) { return island_of_root_[union_find_.Find(d)]; }
  // Island of union-find index `index`, or -1 for a rigid-only island.
  int IslandOf(int index);
  int num_dynamic_bodies() const { return static_cast<int>(dynamic_.size()); }
  // The dynamic rigid body of union-find index `index` (>= num_deformables).
  btRigidBody* dynamic_body(int index) const { return dynamic_[index - num_deformables_]; }
  int num_multibodies() const { return static_cast<int>(multibodies_.size()); }
  // Union-find index of multibody k and the multibody of such an index.
  int multibody_index(int k) const { return first_multibody_ + k; }
  btMultiBody* multibody(int index) const { return multibodies_[index - first_multibody_]; }
  // Union-find index of `body`, -1 when none of its link colliders is movable and in the world.
  int FindMultiBodyIndex(const btMultiBody* body) const;

 private:
  // Numbers the multibodies of the movable link colliders among `objects` after the rigid bodies.
  void NumberMultiBodies(const btCollisionObjectArray& objects);

  int num_deformables_ = 0;
  std::vector<btRigidBody*> dynamic_;  // dynamic rigid bodies, in world array order
  std::vector<int> dynamic_index_;     // union-find index by world array index, -1: not dynamic
  std::vector<btMultiBody*> multibodies_;
  std::vector<int> multibody_index_;  // union-find index by world array index, -1: no link
  int first_multibody_ = 0;
  std::vector<int> island_of_root_;  // island by root (a deformable), -1: none yet
  std::vector<Island> islands_;      // the first num_islands_ are this step's
  int num_islands_ = 0;
  UnionFind union_find_;
};

}  // namespace taut
