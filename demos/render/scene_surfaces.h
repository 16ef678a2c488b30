// The visible surfaces of a scene for pictures: one shaded triangle mesh per body.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demos/scenes/scene.h"
#include "plugin/contact_surface.h"

namespace taut::render {

// A body's surface at one instant, in world coordinates.
struct RenderMesh {
  std::string label;                  // drawn next to the body; empty: none
  std::vector<Vec3> vertices;         // [m]
  std::vector<Triangle> triangles;    // wound outward
  Vec3 colour = Vec3(0.8, 0.8, 0.8);  // linear RGB in [0, 1]
  bool smooth = false;                // vertex normals (scans, spheres); else one normal per face
  bool scenery = false;  // a static body: drawn, but the camera need not show all of it
};

// A deformable body at one instant: its surface (shared between snapshots) and node positions.
struct DeformableState {
  std::shared_ptr<const ContactSurface> surface;
  VecX x;  // (3N) node positions [m]
  std::string label;
  Vec3 colour;
  bool smooth = false;
};

// Everything drawn for one instant of a scene. Deformables are kept as node positions (small
// enough to keep a snapshot per GIF frame of a 26k-vertex scan) and turned into meshes by
// MakeMeshes().
struct SceneSnapshot {
  std::vector<DeformableState> deformables;
  std::vector<RenderMesh> rigid_meshes;
  std::optional<double> ground_z;  // height of a static ground plane z = const, if any [m]
  // Deformable surfaces at their positions, then the rigid meshes.
  std::vector<RenderMesh> MakeMeshes() const;
};

// Extracts snapshots of a scene. Deformable bodies show the surface embedded in them
// (Scene::AttachEmbeddedSurface), else tet bodies their boundary faces and hex bodies their
// lattice boundary; rigid boxes and spheres are drawn as such, a static plane with normal +z
// becomes the ground; other rigid shapes are left out. The boundary of each body model is
// computed once and cached.
class SceneSurfaceExtractor {
 public:
  SceneSnapshot Extract(const Scene& scene);

 private:
  // A cached boundary and the rest positions it was made for (a model removed from the world
  // may be followed by a new one at the same address).
  struct CachedSurface {
    VecX rest_positions;
    int num_elements = 0;
    std::shared_ptr<const ContactSurface> surface;
  };
  // The body's boundary (embedded = -1) or embedded surface `embedded` of the scene.
  std::shared_ptr<const ContactSurface> GetSurface(const Scene& scene, const ElementModel& model,
                                                   int embedded);
  std::map<std::pair<const ElementModel*, int>, CachedSurface> surfaces_;
};

// Colour of the i-th deformable body (a small qualitative palette, repeated).
Vec3 GetBodyColour(int i);

}  // namespace taut::render
