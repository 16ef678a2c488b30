#include "plugin/hex_shapes.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace taut {

namespace internal {

// Keeps the cells of the n[0] x n[1] x n[2] grid over [lo, lo + size] whose centre satisfies
// `inside`, numbering the nodes of kept cells in grid order (x fastest). Hex local node
// a = 4 bi + 2 bj + bk sits at grid node (i + bi, j + bj, k + bk) (hex_lattice.h order).
HexLattice CutGridHexLattice(const Vec3& lo, const Vec3& size, const std::array<int, 3>& n,
                             const std::function<bool(const Vec3&)>& inside,
                             const std::string& source) {
  const Vec3 h(size.x() / n[0], size.y() / n[1], size.z() / n[2]);
  const int px = n[0] + 1, py = n[1] + 1, pz = n[2] + 1;
  auto grid_node = [&](int i, int j, int k) { return i + px * (j + py * k); };
  std::vector<std::array<int, 8>> cells;  // in grid node indices
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 centre = lo + Vec3((i + 0.5) * h.x(), (j + 0.5) * h.y(), (k + 0.5) * h.z());
        if (!inside(centre)) continue;
        std::array<int, 8> cell;
        for (int a = 0; a < 8; ++a)
          cell[a] = grid_node(i + ((a >> 2) & 1), j + ((a >> 1) & 1), k + (a & 1));
        cells.push_back(cell);
      }
  TAUT_DEMAND(!cells.empty(), source, ": no grid cell centre lies inside the shape (cell size ",
              "too large?)");
  // Compact: new index of every used grid node, in grid order.
  std::vector<int> index(static_cast<std::size_t>(px) * py * pz, -1);
  for (const auto& cell : cells)
    for (int g : cell) index[g] = 0;
  HexLattice lattice;
  lattice.source = source;
  for (int k = 0; k < pz; ++k)
    for (int j = 0; j < py; ++j)
      for (int i = 0; i < px; ++i) {
        int& id = index[grid_node(i, j, k)];
        if (id < 0) continue;
        id = static_cast<int>(lattice.nodes.size());
        lattice.nodes.push_back(lo + Vec3(i * h.x(), j * h.y(), k * h.z()));
      }
  for (const auto& cell : cells) {
    std::array<int, 8> hex;
    for (int a = 0; a < 8; ++a) hex[a] = index[cell[a]];
    lattice.hexes.push_back(hex);
  }
  return lattice;
}

// Cells along an extent: max(1, round(extent / cell_size)).
int CountCells(double extent, double cell_size) {
  return std::max(1, static_cast<int>(std::lround(extent / cell_size)));
}

// Throws unless value is finite and positive.
void DemandPositive(double value, const char* what, const char* shape) {
  TAUT_DEMAND(std::isfinite(value) && value > 0.0, shape, " hex lattice: ", what, " = ", value,
              " must be finite and > 0");
}

}  // namespace internal

HexLattice MakeCylinderHexLattice(double length, double radius, double cell_size,
                                  const Vec3& axis_start) {
  internal::DemandPositive(length, "length", "cylinder");
  internal::DemandPositive(radius, "radius", "cylinder");
  internal::DemandPositive(cell_size, "cell size", "cylinder");
  const int nr = internal::CountCells(2.0 * radius, cell_size);
  const std::array<int, 3> n = {internal::CountCells(length, cell_size), nr, nr};
  // Keep cells whose centre is within the radius of the x axis through axis_start.
  auto inside = [&](const Vec3& c) {
    return (c - axis_start).tail<2>().squaredNorm() <= radius * radius;
  };
  return internal::CutGridHexLattice(axis_start - Vec3(0.0, radius, radius),
                                     Vec3(length, 2.0 * radius, 2.0 * radius), n, inside,
                                     "cylinder hex lattice");
}

HexLattice MakeSphereHexLattice(double radius, double cell_size, const Vec3& centre) {
  internal::DemandPositive(radius, "radius", "sphere");
  internal::DemandPositive(cell_size, "cell size", "sphere");
  const int n = internal::CountCells(2.0 * radius, cell_size);
  auto inside = [&](const Vec3& c) { return (c - centre).squaredNorm() <= radius * radius; };
  return internal::CutGridHexLattice(centre - Vec3::Constant(radius), Vec3::Constant(2.0 * radius),
                                     {n, n, n}, inside, "sphere hex lattice");
}

}  // namespace taut
