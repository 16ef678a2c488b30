// Closed triangle surfaces (OFF/OBJ scans, generated shapes): storage, validation, bounds.
#pragma once

#include <string>
#include <vector>

#include "plugin/common.h"
#include "plugin/tet_mesh.h"

namespace taut {

// A triangle surface. Triangles are wound counter-clockwise seen from outside (outward normal
// (b - a) x (c - a)) when the surface is a consistently oriented closed body; vertices that no
// triangle uses are allowed.
struct SurfaceMesh {
  std::vector<Vec3> vertices;       // (num_vertices) positions [m]
  std::vector<Triangle> triangles;  // (num_triangles x 3) vertex indices
  std::string source = "surface";   // file name or generator, used in error messages
};

// Throws InputError naming the source and the triangle or edge when the surface is empty, a vertex
// is not finite, an index is out of range, a triangle repeats a vertex or is degenerate
// (|(b - a) x (c - a)| <= 1e-12 (longest edge)^2), or the surface is not a closed oriented
// 2-manifold: every edge (a, b) must be used by exactly one triangle as a -> b and exactly one as
// b -> a.
void ValidateClosedSurface(const SurfaceMesh& mesh);

// Axis-aligned bounding box of all vertices; throws InputError when there are none.
Eigen::AlignedBox3d CalcSurfaceBounds(const SurfaceMesh& mesh);

// Enclosed volume sum det[a, b, c] / 6 over the triangles (divergence theorem); positive for an
// outward-wound closed surface [m^3].
double CalcSurfaceSignedVolume(const SurfaceMesh& mesh);

// Surface of the box [min_corner, min_corner + size], outward wound, each face split into 2 x n1 x
// n2 triangles on a regular grid of cells per axis (nx, ny, nz).
SurfaceMesh MakeBoxSurface(const Vec3& size, int nx, int ny, int nz,
                           const Vec3& min_corner = Vec3::Zero());

// Icosphere: an icosahedron whose triangles are split in four `subdivisions` times, vertices
// projected onto the sphere of the given radius and centre; outward wound, 20 * 4^subdivisions
// triangles. subdivisions in [0, 7].
// Closed cylinder surface along +x from axis_start, `segments` around, `rings` along, capped by
// triangle fans around a centre vertex; outward wound.
SurfaceMesh MakeCylinderSurface(double length, double radius, int segments, int rings,
                                const Vec3& axis_start = Vec3::Zero());

SurfaceMesh MakeIcosphereSurface(double radius, int subdivisions,
                                 const Vec3& centre = Vec3::Zero());

}  // namespace taut
