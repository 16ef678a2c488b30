#include "bullet_bridge/collision_filter.h"

namespace taut {
namespace {

// Bullet's two-way test: a's group is in b's mask and b's group is in a's mask.
bool GroupsMatch(int group_a, int mask_a, int group_b, int mask_b) {
  return (group_a & mask_b) != 0 && (group_b & mask_a) != 0;
}

}  // namespace

bool ShouldCollide(const btCollisionObject& deformable, const btCollisionObject& other) {
  const btBroadphaseProxy* a = deformable.getBroadphaseHandle();
  const btBroadphaseProxy* b = other.getBroadphaseHandle();
  if (a == nullptr || b == nullptr) return false;
  if (!GroupsMatch(a->m_collisionFilterGroup, a->m_collisionFilterMask, b->m_collisionFilterGroup,
                   b->m_collisionFilterMask))
    return false;
  return deformable.checkCollideWith(&other) && other.checkCollideWith(&deformable);
}

bool PassesQueryFilter(const btCollisionObject& object, const QueryFilter& filter) {
  const btBroadphaseProxy* proxy = object.getBroadphaseHandle();
  if (proxy == nullptr) return false;
  return GroupsMatch(proxy->m_collisionFilterGroup, proxy->m_collisionFilterMask, filter.group,
                     filter.mask);
}

}  // namespace taut
