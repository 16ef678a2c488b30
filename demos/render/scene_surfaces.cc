#include "demos/render/scene_surfaces.h"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <cstdio>

#include "bullet_bridge/eigen_bullet.h"

namespace taut::render {

Vec3 GetBodyColour(int i) {
  // Saturated, distinguishable hues (the test tells bodies from ground and text by saturation).
  static const Vec3 kPalette[] = {Vec3(0.90, 0.33, 0.20), Vec3(0.20, 0.50, 0.85),
                                  Vec3(0.25, 0.70, 0.30), Vec3(0.85, 0.65, 0.10),
                                  Vec3(0.60, 0.30, 0.75), Vec3(0.10, 0.70, 0.70)};
  return kPalette[i % 6];
}

namespace {
constexpr double kRigidColour[3] = {0.55, 0.42, 0.30};  // rigid bodies: brown wood

// Box of half extents h around the origin: 8 corners, 12 outward triangles.
RenderMesh MakeBoxMesh(const Vec3& h) {
  RenderMesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.vertices.push_back(
        Vec3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z()));
  // Faces as quads (counter-clockwise seen from outside).
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  return mesh;
}

// Mesh of a rigid body's shape in its world pose, or nothing for shapes we do not draw.
std::optional<RenderMesh> MakeRigidMesh(const btRigidBody& rigid) {
  const btCollisionShape* shape = rigid.getCollisionShape();
  RenderMesh mesh;
  if (shape->getShapeType() == BOX_SHAPE_PROXYTYPE) {
    const btVector3 h = static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin();
    mesh = MakeBoxMesh(ToEigen(h));
  } else if (shape->getShapeType() == SPHERE_SHAPE_PROXYTYPE) {
    const SurfaceMesh sphere =
        MakeIcosphereSurface(static_cast<const btSphereShape*>(shape)->getRadius(), 2);
    mesh.vertices = sphere.vertices;
    mesh.triangles = sphere.triangles;
    mesh.smooth = true;
  } else {
    return std::nullopt;
  }
  const btTransform& pose = rigid.getWorldTransform();
  for (Vec3& v : mesh.vertices) v = ToEigen(pose * ToBullet(v));
  mesh.colour = Vec3(kRigidColour[0], kRigidColour[1], kRigidColour[2]);
  mesh.scenery = rigid.isStaticObject();
  if (rigid.getInvMass() > 0.0) {
    char label[32];
    std::snprintf(label, sizeof(label), "%g kg", 1.0 / rigid.getInvMass());
    mesh.label = label;
  }
  return mesh;
}
}  // namespace

std::vector<RenderMesh> SceneSnapshot::MakeMeshes() const {
  std::vector<RenderMesh> meshes;
  for (const DeformableState& d : deformables) {
    RenderMesh mesh;
    mesh.label = d.label;
    mesh.colour = d.colour;
    mesh.smooth = d.smooth;
    mesh.vertices.reserve(d.surface->points.size());
    for (const ContactPoint& p : d.surface->points)
      mesh.vertices.push_back(CalcContactPointPosition(p, d.x));
    mesh.triangles = d.surface->triangles;
    meshes.push_back(std::move(mesh));
  }
  meshes.insert(meshes.end(), rigid_meshes.begin(), rigid_meshes.end());
  return meshes;
}

std::shared_ptr<const ContactSurface> SceneSurfaceExtractor::GetSurface(const Scene& scene,
                                                                        const ElementModel& model,
                                                                        int embedded) {
  CachedSurface& cached = surfaces_[{&model, embedded}];
  if (cached.surface == nullptr || cached.num_elements != model.num_elements() ||
      cached.rest_positions.size() != model.rest_positions().size() ||
      cached.rest_positions != model.rest_positions()) {
    cached.rest_positions = model.rest_positions();
    cached.num_elements = model.num_elements();
    if (embedded >= 0) {
      cached.surface = std::make_shared<const ContactSurface>(scene.embedded_surface(embedded));
    } else {
      cached.surface = std::make_shared<const ContactSurface>(MakeBodyContactSurface(model));
    }
  }
  return cached.surface;
}

SceneSnapshot SceneSurfaceExtractor::Extract(const Scene& scene) {
  SceneSnapshot snapshot;
  std::vector<int> embedded(scene.num_deformable_bodies(), -1);
  for (int i = 0; i < scene.num_embedded_surfaces(); ++i)
    embedded[scene.embedded_surface_body(i)] = i;
  for (int b = 0; b < scene.num_deformable_bodies(); ++b) {
    const DeformableBody& body = scene.deformable_body(b);
    DeformableState state;
    state.surface = GetSurface(scene, body.model(), embedded[b]);
    state.x = body.x();
    state.label = body.name();
    state.colour = GetBodyColour(b);
    state.smooth = embedded[b] >= 0;
    snapshot.deformables.push_back(std::move(state));
  }
  const btCollisionObjectArray& objects = scene.collision_objects();
  for (int i = 0; i < objects.size(); ++i) {
    const btRigidBody* rigid = btRigidBody::upcast(objects[i]);
    if (rigid == nullptr) continue;
    const btCollisionShape* shape = rigid->getCollisionShape();
    if (shape->getShapeType() == STATIC_PLANE_PROXYTYPE) {
      const auto* plane = static_cast<const btStaticPlaneShape*>(shape);
      const btTransform& pose = rigid->getWorldTransform();
      const btVector3 n = pose.getBasis() * plane->getPlaneNormal();
      if (n.z() > 0.999) {
        const double z = (pose * (plane->getPlaneNormal() * plane->getPlaneConstant())).z();
        snapshot.ground_z = snapshot.ground_z ? std::max(*snapshot.ground_z, z) : z;
      }
      continue;
    }
    if (std::optional<RenderMesh> mesh = MakeRigidMesh(*rigid))
      snapshot.rigid_meshes.push_back(std::move(*mesh));
  }
  return snapshot;
}

}  // namespace taut::render
