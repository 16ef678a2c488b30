#include "plugin/hex_voxelizer.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace taut {
namespace {

constexpr double kMaxCells = 5e7;

// The regular grid of VoxelizeSurface: cell (i, j, k) spans origin + h [i, i+1] x [j, j+1] x
// [k, k+1].
struct Grid {
  Vec3 origin;
  double h = 0.0;
  int n[3] = {0, 0, 0};
  // Centre of cell (i, j, k).
  Vec3 Centre(int i, int j, int k) const { return origin + h * Vec3(i + 0.5, j + 0.5, k + 0.5); }
};

// Grid over bounds with cells of edge h, centred on the bounds.
Grid MakeGrid(const Eigen::AlignedBox3d& bounds, double h, const std::string& source) {
  TAUT_DEMAND(std::isfinite(h) && h > 0.0, source, ": cell size must be finite and > 0, got ", h);
  TAUT_DEMAND(!bounds.isEmpty() && bounds.min().allFinite() && bounds.max().allFinite(), source,
              ": bounds must be finite and non-empty");
  Grid grid;
  grid.h = h;
  const Vec3 extent = bounds.sizes();
  double total = 1.0;
  for (int d = 0; d < 3; ++d) {
    const double cells = std::max(1.0, std::ceil(extent[d] / h * (1.0 - 1e-9)));
    total *= cells;
    TAUT_DEMAND(total <= kMaxCells, source, ": cell size ", h, " m gives more than ", kMaxCells,
                " grid cells over bounds of size ", extent.transpose(), " m");
    grid.n[d] = static_cast<int>(cells);
  }
  grid.origin = bounds.center() - 0.5 * h * Vec3(grid.n[0], grid.n[1], grid.n[2]);
  return grid;
}

// Builds the lattice of the kept cells (kept[i + n0 (j + n1 k)]).
HexLattice BuildLattice(const Grid& g, const std::vector<char>& kept, const std::string& source) {
  const int nx = g.n[0], ny = g.n[1], nz = g.n[2];
  const auto node_id = [&](int i, int j, int k) {
    return static_cast<std::size_t>(i) + (nx + 1) * (j + static_cast<std::size_t>(ny + 1) * k);
  };
  std::vector<int> compact(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1), -1);
  std::size_t cell = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++cell)
        if (kept[cell])
          for (int a = 0; a < 8; ++a)
            compact[node_id(i + ((a >> 2) & 1), j + ((a >> 1) & 1), k + (a & 1))] = 0;
  HexLattice lattice;
  lattice.source = source;
  std::size_t id = 0;
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i, ++id)
        if (compact[id] == 0) {
          compact[id] = static_cast<int>(lattice.nodes.size());
          lattice.nodes.push_back(g.origin + g.h * Vec3(i, j, k));
        }
  cell = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++cell)
        if (kept[cell]) {
          std::array<int, 8> hex;
          // Local a = 4 bi + 2 bj + bk sits at corner (i + bi, j + bj, k + bk), as in
          // MakeBoxHexLattice.
          for (int a = 0; a < 8; ++a)
            hex[a] = compact[node_id(i + ((a >> 2) & 1), j + ((a >> 1) & 1), k + (a & 1))];
          lattice.hexes.push_back(hex);
        }
  TAUT_DEMAND(!lattice.hexes.empty(), source,
              ": no cell centre lies inside the shape at cell size ", g.h, " m (grid ", nx, "x", ny,
              "x", nz, ")");
  return lattice;
}

// Sign (+1, -1, or 0 for a zero-length edge) of orient(a, b, p) = (b - a) x (p - a) in the (y, z)
// plane with p moved to p + (eps, eps^2): the exact value when non-zero, else the eps and eps^2
// terms -(b_z - a_z) and (b_y - a_y) (simulation of simplicity).
int PerturbedSide(const Vec3& a, const Vec3& b, double py, double pz) {
  const double by = b.y() - a.y(), bz = b.z() - a.z();
  const double o = by * (pz - a.z()) - bz * (py - a.y());
  if (o != 0.0) return o > 0.0 ? 1 : -1;
  if (bz != 0.0) return bz < 0.0 ? 1 : -1;
  return by > 0.0 ? 1 : (by < 0.0 ? -1 : 0);
}

// PerturbedSide of the directed edge u -> v, always evaluated as min -> max (negated when
// u > v), so the two triangles sharing an edge get exactly opposite answers.
int EdgeSide(const std::vector<Vec3>& X, int u, int v, double py, double pz) {
  return u < v ? PerturbedSide(X[u], X[v], py, pz) : -PerturbedSide(X[v], X[u], py, pz);
}

}  // namespace

HexLattice VoxelizeSurface(const std::function<bool(const Vec3&)>& inside,
                           const Eigen::AlignedBox3d& bounds, double cell_size,
                           const std::string& source) {
  TAUT_DEMAND(static_cast<bool>(inside), source, ": no inside test given");
  const Grid g = MakeGrid(bounds, cell_size, source);
  std::vector<char> kept(static_cast<std::size_t>(g.n[0]) * g.n[1] * g.n[2], 0);
  std::size_t cell = 0;
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i, ++cell) kept[cell] = inside(g.Centre(i, j, k)) ? 1 : 0;
  return BuildLattice(g, kept, source);
}

HexLattice VoxelizeSurface(const SurfaceMesh& mesh, double cell_size) {
  ValidateClosedSurface(mesh);
  const Grid g = MakeGrid(CalcSurfaceBounds(mesh), cell_size, mesh.source);
  const int ny = g.n[1], nz = g.n[2];
  const std::vector<Vec3>& X = mesh.vertices;
  // Crossings (x, +-1) of each row's ray line {y = y_j, z = z_k} with the surface.
  std::vector<std::vector<std::pair<double, int>>> rows(static_cast<std::size_t>(ny) * nz);
  for (const Triangle& t : mesh.triangles) {
    const Vec3 &a = X[t[0]], &b = X[t[1]], &c = X[t[2]];
    // Rows whose centre line may meet the triangle's (y, z) bounding box, widened by one row.
    const auto range = [&](int d, int n, int& lo, int& hi) {
      const double mn = std::min({a[d], b[d], c[d]}), mx = std::max({a[d], b[d], c[d]});
      lo = std::max(0, static_cast<int>(std::floor((mn - g.origin[d]) / g.h - 0.5)) - 1);
      hi = std::min(n - 1, static_cast<int>(std::ceil((mx - g.origin[d]) / g.h - 0.5)) + 1);
    };
    int j0, j1, k0, k1;
    range(1, ny, j0, j1);
    range(2, nz, k0, k1);
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        const Vec3 p = g.Centre(0, j, k);
        const int s0 = EdgeSide(X, t[0], t[1], p.y(), p.z());
        const int s1 = EdgeSide(X, t[1], t[2], p.y(), p.z());
        const int s2 = EdgeSide(X, t[2], t[0], p.y(), p.z());
        if (s0 == 0 || s0 != s1 || s1 != s2) continue;
        // Barycentric (u, v) of p in the (y, z) projection, then x on the triangle's plane.
        const double e1y = b.y() - a.y(), e1z = b.z() - a.z();
        const double e2y = c.y() - a.y(), e2z = c.z() - a.z();
        const double det = e1y * e2z - e1z * e2y;
        double x = (a.x() + b.x() + c.x()) / 3.0;  // projection degenerate to round-off
        if (det != 0.0) {
          const double py = p.y() - a.y(), pz = p.z() - a.z();
          const double u = (py * e2z - pz * e2y) / det, v = (e1y * pz - e1z * py) / det;
          x = a.x() + u * (b.x() - a.x()) + v * (c.x() - a.x());
        }
        // All sides agree with the projected orientation, i.e. the sign of n_x.
        rows[static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * k].emplace_back(x, s0);
      }
  }
  std::vector<char> kept(static_cast<std::size_t>(g.n[0]) * ny * nz, 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      auto& row = rows[static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * k];
      std::sort(row.begin(), row.end());
      // Winding number at x = sum of the signs of crossings beyond x; sweep from +x down.
      int winding = 0;
      std::size_t next = row.size();
      for (int i = g.n[0] - 1; i >= 0; --i) {
        const double xc = g.Centre(i, j, k).x();
        while (next > 0 && row[next - 1].first > xc) winding += row[--next].second;
        kept[static_cast<std::size_t>(i) + g.n[0] * (j + static_cast<std::size_t>(ny) * k)] =
            winding != 0 ? 1 : 0;
      }
    }
  return BuildLattice(g, kept, mesh.source);
}

}  // namespace taut
