#include "plugin/embedded_surface.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>

namespace taut {
namespace {

// Trilinear weights N_a(s) = prod_k (1 + s_ak s_k) / 8, valid (extrapolating) for any s.
std::array<double, 8> CalcTrilinearWeights(const Vec3& s) {
  std::array<double, 8> N;
  for (int a = 0; a < 8; ++a) {
    const Vec3 sa = HexCornerSign(a);
    N[a] = (1.0 + sa.x() * s.x()) * (1.0 + sa.y() * s.y()) * (1.0 + sa.z() * s.z()) / 8.0;
  }
  return N;
}

// Appends the shortest decimal text that reads back as exactly v.
void AppendReal(std::string& out, double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v);
  out.append(buffer, ec == std::errc() ? end : buffer);
}

}  // namespace

EmbeddedSurface EmbedSurface(const HexLattice& lattice, const SurfaceMesh& mesh) {
  const std::string& src = lattice.source;
  TAUT_DEMAND(!lattice.hexes.empty(), src, ": cannot embed ", mesh.source, " in an empty lattice");
  TAUT_DEMAND(!mesh.vertices.empty(), mesh.source, ": cannot embed a surface without vertices");
  const int num_nodes = static_cast<int>(lattice.nodes.size());
  for (std::size_t e = 0; e < lattice.hexes.size(); ++e)
    for (int n : lattice.hexes[e])
      TAUT_DEMAND(n >= 0 && n < num_nodes, src, ": element ", e, " refers to node ", n,
                  " but the lattice has ", num_nodes, " nodes");
  // Grid from hex 0: origin at its node 0 (corner s = (-1,-1,-1)), cell = node 7 - node 0.
  const auto& h0 = lattice.hexes[0];
  const Vec3 origin = lattice.nodes[h0[0]];
  const Vec3 cell = lattice.nodes[h0[7]] - origin;
  TAUT_DEMAND(cell.allFinite() && (cell.array() > 0.0).all(), src,
              ": element 0 is not an axis-aligned box with positive edges");
  const double tol = 1e-9 * cell.maxCoeff();
  std::map<std::array<long long, 3>, int> hex_of_cell;
  for (std::size_t e = 0; e < lattice.hexes.size(); ++e) {
    const Vec3 X0 = lattice.nodes[lattice.hexes[e][0]];
    const Vec3 q = (X0 - origin).cwiseQuotient(cell);
    std::array<long long, 3> ijk;
    for (int d = 0; d < 3; ++d) {
      TAUT_DEMAND(std::isfinite(q[d]) && std::abs(q[d]) < 1e15, src, ": element ", e,
                  " has a non-finite or far-off corner");
      ijk[d] = std::llround(q[d]);
    }
    for (int a = 0; a < 8; ++a) {
      const Vec3 expected =
          origin + cell.cwiseProduct(
                       Vec3(ijk[0] + ((a >> 2) & 1), ijk[1] + ((a >> 1) & 1), ijk[2] + (a & 1)));
      TAUT_DEMAND((lattice.nodes[lattice.hexes[e][a]] - expected).cwiseAbs().maxCoeff() <= tol, src,
                  ": element ", e, " node ", a, " is not on the regular grid of element 0 (cell ",
                  cell.transpose(), " m); EmbedSurface needs an axis-aligned regular lattice");
    }
    TAUT_DEMAND(hex_of_cell.emplace(ijk, static_cast<int>(e)).second, src, ": elements ",
                hex_of_cell[ijk], " and ", e, " occupy the same cell");
  }
  EmbeddedSurface out;
  out.source = mesh.source;
  out.triangles = mesh.triangles;
  out.vertices.resize(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3& X = mesh.vertices[v];
    TAUT_DEMAND(X.allFinite(), mesh.source, ": vertex ", v, " has a non-finite coordinate");
    const Vec3 q = (X - origin).cwiseQuotient(cell);
    // The cell floor(q) holds X; within 1e-9 cells of a cell face, the neighbour across it also
    // does (so vertices on the lattice's max faces are inside, not extrapolated).
    int hex = -1;
    if ((q.cwiseAbs().array() < 1e15).all()) {
      long long lo[3], hi[3];
      for (int d = 0; d < 3; ++d) {
        const double f = std::floor(q[d]);
        lo[d] = static_cast<long long>(f) - (q[d] - f <= 1e-9 ? 1 : 0);
        hi[d] = static_cast<long long>(f) + (q[d] - f >= 1.0 - 1e-9 ? 1 : 0);
      }
      for (long long i = hi[0]; hex < 0 && i >= lo[0]; --i)
        for (long long j = hi[1]; hex < 0 && j >= lo[1]; --j)
          for (long long k = hi[2]; hex < 0 && k >= lo[2]; --k) {
            const auto it = hex_of_cell.find({i, j, k});
            if (it != hex_of_cell.end()) hex = it->second;
          }
    }
    if (hex < 0) {
      // Outside every hex: nearest centre, weights extrapolated.
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t e = 0; e < lattice.hexes.size(); ++e) {
        const Vec3 centre = lattice.nodes[lattice.hexes[e][0]] + 0.5 * cell;
        const double d2 = (X - centre).squaredNorm();
        if (d2 < best) {
          best = d2;
          hex = static_cast<int>(e);
        }
      }
      ++out.num_extrapolated;
    }
    // s = 2 (X - centre) / cell, componentwise.
    const Vec3 centre = lattice.nodes[lattice.hexes[hex][0]] + 0.5 * cell;
    EmbeddedVertex& ev = out.vertices[v];
    ev.hex = hex;
    ev.s = 2.0 * (X - centre).cwiseQuotient(cell);
    ev.weights = CalcTrilinearWeights(ev.s);
  }
  return out;
}

std::vector<Vec3> CalcEmbeddedPositions(const EmbeddedSurface& surface, const HexLattice& lattice,
                                        const VecX& x) {
  const std::size_t num_nodes = lattice.nodes.size();
  TAUT_DEMAND(static_cast<std::size_t>(x.size()) == 3 * num_nodes, surface.source,
              ": node positions have ", x.size(), " entries, expected 3 x ", num_nodes);
  std::vector<Vec3> positions(surface.vertices.size(), Vec3::Zero());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
    const EmbeddedVertex& ev = surface.vertices[v];
    TAUT_DEMAND(ev.hex >= 0 && static_cast<std::size_t>(ev.hex) < lattice.hexes.size(),
                surface.source, ": vertex ", v, " refers to hex ", ev.hex, " but ", lattice.source,
                " has ", lattice.hexes.size());
    for (int a = 0; a < 8; ++a) {
      const int n = lattice.hexes[ev.hex][a];
      TAUT_DEMAND(n >= 0 && static_cast<std::size_t>(n) < num_nodes, lattice.source, ": element ",
                  ev.hex, " refers to node ", n);
      positions[v] += ev.weights[a] * x.segment<3>(3 * n);
    }
  }
  return positions;
}

void WriteEmbeddedSurfaceObj(const std::string& path, const std::vector<Vec3>& positions,
                             const std::vector<Triangle>& triangles) {
  std::string out = "# taut embedded surface\n";
  for (const Vec3& p : positions) {
    out += 'v';
    for (int d = 0; d < 3; ++d) {
      out += ' ';
      AppendReal(out, p[d]);
    }
    out += '\n';
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    out += 'f';
    for (int i : triangles[t]) {
      TAUT_DEMAND(i >= 0 && static_cast<std::size_t>(i) < positions.size(), "OBJ file '", path,
                  "': triangle ", t, " refers to vertex ", i, " but there are ", positions.size(),
                  " positions");
      out += ' ' + std::to_string(i + 1);
    }
    out += '\n';
  }
  std::ofstream file(path, std::ios::binary);
  TAUT_DEMAND(file.good(), "OBJ file '", path, "': cannot open for writing");
  file << out;
  file.close();
  TAUT_DEMAND(!file.fail(), "OBJ file '", path, "': write failed");
}

}  // namespace taut
