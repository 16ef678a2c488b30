// Voxelization of closed surfaces and procedural shapes into regular hex lattices.
#pragma once

#include <functional>
#include <string>

#include "plugin/hex_lattice.h"
#include "plugin/surface_mesh.h"

namespace taut {

// Cubic cells of edge cell_size on a grid that covers bounds: n_d = ceil(extent_d / cell_size)
// cells per axis (at least 1, a relative slack of 1e-9 so an exact multiple is not rounded up),
// centred on the bounds, so a box whose faces lie on multiples of cell_size from its min corner
// gets exactly its cells. A cell is kept when inside(centre) is true. Nodes shared between kept
// cells are merged and numbered compactly in grid order (x fastest, then y, then z); hexes are
// listed in grid order with the local node order of HexLattice. Throws InputError when cell_size
// is not finite and > 0, the bounds are empty or not finite, the grid would exceed 5e7 cells, or no
// cell is kept.
HexLattice VoxelizeSurface(const std::function<bool(const Vec3&)>& inside,
                           const Eigen::AlignedBox3d& bounds, double cell_size,
                           const std::string& source = "voxelized shape");

// Voxelizes a closed surface (ValidateClosedSurface runs first) on the grid above over
// CalcSurfaceBounds(mesh). Inside test: the signed number of crossings of the ray from the cell
// centre along +x with the triangles (+1 where the triangle's normal has n_x > 0, -1 where n_x <
// 0), i.e. the winding number of the surface around the centre; a centre is inside when it is
// non-zero, so inverted (inward-wound) surfaces work too. Rays through edges or vertices are
// decided by simulation of simplicity: the ray is moved by (eps, eps^2) in (y, z), and each edge
// side test is evaluated once per edge (in a fixed vertex order), so the two triangles of a shared
// edge always agree and no crossing is counted twice or lost. A centre exactly on the surface may
// go either way. Cost O(num_triangles + crossings + cells).
HexLattice VoxelizeSurface(const SurfaceMesh& mesh, double cell_size);

}  // namespace taut
