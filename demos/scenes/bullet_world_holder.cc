#include "demos/scenes/bullet_world_holder.h"

namespace taut {

BulletWorldHolder::BulletWorldHolder() { world.setGravity(btVector3(0, 0, -9.81)); }

BulletWorldHolder::~BulletWorldHolder() {
  for (auto& body : rigid_bodies) world.removeRigidBody(body.get());
}

}  // namespace taut
