#include "plugin/hex_lattice.h"

#include <algorithm>
#include <cmath>

#include "plugin/box_tet_mesher.h"

namespace taut {

Vec3 HexGaussPoint(int q) { return HexCornerSign(q) / std::sqrt(3.0); }

Eigen::Matrix<double, 8, 3> CalcHexShapeGradients(const Vec3& s) {
  Eigen::Matrix<double, 8, 3> H;
  for (int a = 0; a < 8; ++a) {
    const Vec3 sa = HexCornerSign(a);
    const Vec3 f = (Vec3::Ones() + sa.cwiseProduct(s)) / 2.0;  // (1 + s_ak s_k) / 2
    // dN_a/ds_k = s_ak / 2 * prod_{l != k} (1 + s_al s_l) / 2.
    H(a, 0) = 0.5 * sa.x() * f.y() * f.z();
    H(a, 1) = 0.5 * sa.y() * f.x() * f.z();
    H(a, 2) = 0.5 * sa.z() * f.x() * f.y();
  }
  return H;
}

Mat3 CalcHexJacobian(const std::array<Vec3, 8>& X, const Vec3& s) {
  const Eigen::Matrix<double, 8, 3> H = CalcHexShapeGradients(s);
  Mat3 F = Mat3::Zero();
  for (int a = 0; a < 8; ++a) F += X[a] * H.row(a);
  return F;
}

void ValidateHexLattice(const HexLattice& lattice) {
  const std::string& src = lattice.source;
  TAUT_DEMAND(!lattice.nodes.empty(), src, ": lattice has no nodes");
  TAUT_DEMAND(!lattice.hexes.empty(), src, ": lattice has no hexahedra");
  const int n = static_cast<int>(lattice.nodes.size());
  for (int i = 0; i < n; ++i)
    TAUT_DEMAND(lattice.nodes[i].allFinite(), src, ": node ", i, " has a non-finite coordinate");
  for (size_t e = 0; e < lattice.hexes.size(); ++e) {
    const auto& h = lattice.hexes[e];
    for (int a = 0; a < 8; ++a) {
      TAUT_DEMAND(h[a] >= 0 && h[a] < n, src, ": element ", e, " refers to node ", h[a],
                  " but the lattice has ", n, " nodes");
      for (int b = 0; b < a; ++b)
        TAUT_DEMAND(h[a] != h[b], src, ": element ", e, " repeats node ", h[a]);
    }
    std::array<Vec3, 8> X;
    for (int a = 0; a < 8; ++a) X[a] = lattice.nodes[h[a]];
    double longest = 0.0;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < a; ++b) longest = std::max(longest, (X[a] - X[b]).norm());
    const double scale = 1e-12 * longest * longest * longest;
    for (int q = 0; q < 8; ++q) {
      const double det = CalcHexJacobian(X, HexGaussPoint(q)).determinant();
      TAUT_DEMAND(det > scale, src, ": element ", e, " is ", det < 0.0 ? "inverted" : "degenerate",
                  " (det dX/ds = ", det, " m^3 at Gauss point ", q,
                  "; expected > 0 with the node order of docs/math.md §4.1)");
    }
  }
}

HexLattice MakeBoxHexLattice(const Vec3& size, int nx, int ny, int nz, const Vec3& min_corner) {
  TAUT_DEMAND(nx > 0 && ny > 0 && nz > 0, "box hex lattice: cell counts must be > 0, got ", nx, "x",
              ny, "x", nz);
  TAUT_DEMAND(size.allFinite() && (size.array() > 0.0).all(),
              "box hex lattice: size must be finite and > 0, got ", size.transpose());
  TAUT_DEMAND(min_corner.allFinite(), "box hex lattice: min corner must be finite");
  HexLattice lattice;
  lattice.source = internal::Concat("box hex ", nx, "x", ny, "x", nz);
  const Vec3 cell = size.cwiseQuotient(Vec3(nx, ny, nz));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        lattice.nodes.push_back(min_corner + Vec3(i * cell.x(), j * cell.y(), k * cell.z()));
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        std::array<int, 8> hex;
        // Local a = 4 bi + 2 bj + bk sits at cell corner (i + bi, j + bj, k + bk).
        for (int a = 0; a < 8; ++a)
          hex[a] = BoxNodeIndex(i + ((a >> 2) & 1), j + ((a >> 1) & 1), k + (a & 1), nx, ny);
        lattice.hexes.push_back(hex);
      }
  return lattice;
}

}  // namespace taut
