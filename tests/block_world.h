// A test world holding one tet block "block" and static collision objects (not rigid bodies) in
// a collision group and mask, removed from the world before it goes.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <stdexcept>
#include <vector>

#include "bullet_bridge/deformable_world.h"
#include "plugin/box_tet_mesher.h"

namespace taut {

struct BlockWorld {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  DeformableWorld world{&dispatcher, &broadphase, &solver, &configuration};
  DeformableBody* block = nullptr;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> objects;

  // The block: `mesh` of a soft material (E = 100 kPa, nu = 0.3, 1000 kg/m^3), gravity g [m/s^2].
  BlockWorld(const TetMesh& mesh, const btVector3& gravity) {
    world.setGravity(gravity);
    DeformableBodySettings settings;
    settings.name = "block";
    settings.material = {1e5, 0.3, 1000};
    block = world.AddTetBody(mesh, settings);
  }
  ~BlockWorld() {
    for (auto& object : objects) world.removeCollisionObject(object.get());
  }
  // A static object with `shape` (owned from here on) at `position`, in `group` with `mask`.
  btCollisionObject* AddObject(btCollisionShape* shape, const btVector3& position,
                               int group = btBroadphaseProxy::DefaultFilter,
                               int mask = btBroadphaseProxy::AllFilter) {
    shapes.emplace_back(shape);
    objects.push_back(std::make_unique<btCollisionObject>());
    objects.back()->setCollisionShape(shape);
    objects.back()->setWorldTransform(btTransform(btQuaternion::getIdentity(), position));
    world.addCollisionObject(objects.back().get(), group, mask);
    return objects.back().get();
  }
  // The block's collision object.
  btCollisionObject& BlockObject() {
    const btCollisionObjectArray& all = world.getCollisionObjectArray();
    for (int i = 0; i < all.size(); ++i)
      if (all[i]->getUserPointer() == block) return *all[i];
    throw std::logic_error("block not in the world");
  }
};

}  // namespace taut
