// Procedural tet meshes of unions of capsules (a finger as three phalanges, paper A §5.2).
#pragma once

#include <vector>

#include "plugin/tet_mesh.h"

namespace taut {

// The points within `radius` of the segment [a, b] [m].
struct Capsule {
  Vec3 a = Vec3::Zero();
  Vec3 b = Vec3::Zero();
  double radius = 0.0;
};

// Signed distance to the union of capsules, min_i (|p - P_i(p)| - r_i) with P_i the closest point
// of segment i (exact outside the union, negative inside) [m]. `gradient` (optional) receives the
// unit direction of steepest increase, from the nearest segment towards p.
double CalcCapsuleUnionDistance(const std::vector<Capsule>& capsules, const Vec3& p,
                                Vec3* gradient = nullptr);

// How a union of capsules is cut into tets.
struct CapsuleMeshSettings {
  // Target cell edge per axis [m], > 0. The grid spans the union's bounding box with
  // n = max(1, round(extent / cell)) cells per axis, so the actual cells are extent / n.
  Vec3 cell_size = Vec3(0.01, 0.006, 0.006);
  // A cell is kept when the signed distance of its centre is below keep_offset * (smallest
  // actual cell edge): 0 keeps centres inside, > 0 also keeps cells just outside. In [0, 1].
  double keep_offset = 0.25;
  // Move every boundary node onto the union's surface (a rounded body instead of a voxel one).
  bool snap_boundary = true;
};

// Kuhn-subdivided voxel mesh of the union: the kept cells of the grid, 6 tets each around their
// (0,0,0)-(1,1,1) diagonal (conforming, as MakeBoxTetMesh), unused grid nodes dropped, then the
// boundary nodes projected onto the surface along the distance gradient. The result is validated
// (ValidateTetMesh). Throws InputError for an empty or non-finite capsule list, a non-positive
// radius or cell size, a keep_offset outside [0, 1], no kept cell, or a snapped mesh that inverts
// (then use smaller cells or snap_boundary = false).
TetMesh MakeCapsuleUnionTetMesh(const std::vector<Capsule>& capsules,
                                const CapsuleMeshSettings& settings = CapsuleMeshSettings());

// A finger of the given length along +x from the origin (proximal end at x = 0, tip at x =
// length): three co-axial phalanges of radius 9, 8.5 and 8 mm (scaled with length / 0.07 m) whose
// segments split the length between the end caps 35 : 25 : 18.
std::vector<Capsule> MakeFingerCapsules(double length = 0.07);

}  // namespace taut
