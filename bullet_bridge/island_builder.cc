#include "bullet_bridge/island_builder.h"

#include <BulletCollision/BroadphaseCollision/btDispatcher.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>

#include "bullet_bridge/deformable_collision_object.h"

namespace taut {

bool IslandBuilder::IsDynamicRigidBody(const btCollisionObject& object) {
  const btRigidBody* rigid = btRigidBody::upcast(&object);
  return rigid != nullptr && !rigid->isStaticOrKinematicObject() &&
         rigid->getCollisionShape()->getShapeType() != kDeformableShapeType;
}

void IslandBuilder::Reset(int num_deformables, const btCollisionObjectArray& objects) {
  num_deformables_ = num_deformables;
  dynamic_.clear();
  dynamic_index_.assign(objects.size(), -1);
  for (int i = 0; i < objects.size(); ++i) {
    if (!IsDynamicRigidBody(*objects[i])) continue;
    dynamic_index_[i] = num_deformables + static_cast<int>(dynamic_.size());
    dynamic_.push_back(btRigidBody::upcast(objects[i]));
  }
  NumberMultiBodies(objects);
  union_find_.Reset(first_multibody_ + static_cast<int>(multibodies_.size()));
  num_islands_ = 0;
}

void IslandBuilder::NumberMultiBodies(const btCollisionObjectArray& objects) {
  first_multibody_ = num_deformables_ + static_cast<int>(dynamic_.size());
  multibodies_.clear();
  multibody_index_.assign(objects.size(), -1);
  for (int i = 0; i < objects.size(); ++i) {
    const btMultiBodyLinkCollider* link = btMultiBodyLinkCollider::upcast(objects[i]);
    if (link == nullptr || link->m_multiBody == nullptr || link->isStaticOrKinematicObject())
      continue;
    auto found = std::find(multibodies_.begin(), multibodies_.end(), link->m_multiBody);
    multibody_index_[i] = first_multibody_ + static_cast<int>(found - multibodies_.begin());
    if (found == multibodies_.end()) multibodies_.push_back(link->m_multiBody);
  }
}

int IslandBuilder::FindMultiBodyIndex(const btMultiBody* body) const {
  const auto found = std::find(multibodies_.begin(), multibodies_.end(), body);
  return found == multibodies_.end()
             ? -1
             : first_multibody_ + static_cast<int>(found - multibodies_.begin());
}

int IslandBuilder::MultiBodyIndex(const btCollisionObject& object) const {
  const int i = object.getWorldArrayIndex();
  return i >= 0 && i < static_cast<int>(multibody_index_.size()) ? multibody_index_[i] : -1;
}

int IslandBuilder::DynamicIndex(const btCollisionObject& object) const {
  const int i = object.getWorldArrayIndex();
  return i >= 0 && i < static_cast<int>(dynamic_index_.size()) ? dynamic_index_[i] : -1;
}

void IslandBuilder::UniteTouchingRigidBodies(btDispatcher& dispatcher) {
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
    if (manifold->getNumContacts() == 0) continue;
    const int a = DynamicIndex(*manifold->getBody0());
    const int b = DynamicIndex(*manifold->getBody1());
    if (a >= 0 && b >= 0) union_find_.Unite(a, b);
  }
}

void IslandBuilder::UniteJointedRigidBodies(const btDynamicsWorld& world) {
  for (int j = 0; j < world.getNumConstraints(); ++j) {
    const btTypedConstraint* joint = world.getConstraint(j);
    if (!joint->isEnabled()) continue;
    const int a = DynamicIndex(joint->getRigidBodyA());
    const int b = DynamicIndex(joint->getRigidBodyB());
    if (a >= 0 && b >= 0) union_find_.Unite(a, b);
  }
}

void IslandBuilder::MakeDeformableIslands(int& next_source_id) {
  island_of_root_.assign(num_deformables_, -1);
  num_islands_ = 0;
  for (int d = 0; d < num_deformables_; ++d) {
    const int root = union_find_.Find(d);
    if (island_of_root_[root] >= 0) continue;
    if (static_cast<int>(islands_.size()) <= num_islands_) islands_.emplace_back();
    Island& island = islands_[num_islands_];
    island.bodies.clear();
    island.sources.clear();
    if (island.manifolds == nullptr)
      island.manifolds = std::make_unique<RigidManifoldSource>(next_source_id++);
    if (island.joints == nullptr) island.joints = std::make_unique<JointSource>(next_source_id++);
    island.manifolds->Clear();
    island.joints->Clear();
    island.first_deformable = d;
    island_of_root_[root] = num_islands_++;
  }
}

std::vector<std::array<int, 2>> IslandBuilder::SaveSourceIds() const {
  std::vector<std::array<int, 2>> ids;
  for (const Island& island : islands_)
    ids.push_back({island.manifolds->source_id(), island.joints->source_id()});
  return ids;
}

void IslandBuilder::RestoreSourceIds(const std::vector<std::array<int, 2>>& ids) {
  islands_.resize(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    Island& island = islands_[i];
    island.bodies.clear();
    island.sources.clear();
    if (island.manifolds == nullptr || island.manifolds->source_id() != ids[i][0])
      island.manifolds = std::make_unique<RigidManifoldSource>(ids[i][0]);
    if (island.joints == nullptr || island.joints->source_id() != ids[i][1])
      island.joints = std::make_unique<JointSource>(ids[i][1]);
  }
  num_islands_ = 0;
}

int IslandBuilder::IslandOf(int index) {
  const int root = union_find_.Find(index);
  return root < num_deformables_ ? island_of_root_[root] : -1;
}

}  // namespace taut
