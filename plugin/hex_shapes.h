// Procedural hex lattices of simple solids, cut from a box grid (cells whose centre is inside).
#pragma once

#include "plugin/hex_lattice.h"

namespace taut {

// Cylinder of the given length along +x from axis_start, radius around the axis. The box grid
// covers [0, length] x [-radius, radius]^2 (relative to axis_start) with
// n = max(1, round(extent / cell_size)) cells per axis, so the cells are length/n_x by
// 2 radius/n_r; a cell is kept when its centre is within `radius` of the axis. Nodes are compacted
// (only nodes of kept cells, in grid order x fastest). The x = axis_start.x() end face is where a
// cantilever is fixed. Throws InputError for non-positive or non-finite sizes or when no cell is
// kept.
HexLattice MakeCylinderHexLattice(double length, double radius, double cell_size,
                                  const Vec3& axis_start = Vec3::Zero());

// Ball of the given radius around centre, from a grid over centre + [-radius, radius]^3 with
// n = max(1, round(2 radius / cell_size)) cells per axis; cells whose centre is inside the ball
// are kept. Same node numbering and errors as MakeCylinderHexLattice.
HexLattice MakeSphereHexLattice(double radius, double cell_size, const Vec3& centre = Vec3::Zero());

}  // namespace taut
