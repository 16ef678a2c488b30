#include "plugin/box_tet_mesher.h"

#include <algorithm>
#include <utility>

namespace taut {

TetMesh MakeBoxTetMesh(const Vec3& size, int nx, int ny, int nz, const Vec3& min_corner) {
  TAUT_DEMAND(nx > 0 && ny > 0 && nz > 0, "box tet mesh: cell counts must be > 0, got ", nx, "x",
              ny, "x", nz);
  TAUT_DEMAND(size.allFinite() && (size.array() > 0.0).all(),
              "box tet mesh: size must be finite and > 0, got ", size.transpose());
  TetMesh mesh;
  mesh.source = internal::Concat("box ", nx, "x", ny, "x", nz);
  const Vec3 cell = size.cwiseQuotient(Vec3(nx, ny, nz));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.nodes.push_back(min_corner + Vec3(i * cell.x(), j * cell.y(), k * cell.z()));
  // Kuhn split: one tet per axis permutation, walking 000 -> 111 one axis at a time.
  static constexpr int kPerms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& perm : kPerms) {
          int c[3] = {i, j, k};
          std::array<int, 4> tet;
          tet[0] = BoxNodeIndex(c[0], c[1], c[2], nx, ny);
          for (int step = 0; step < 3; ++step) {
            c[perm[step]]++;
            tet[step + 1] = BoxNodeIndex(c[0], c[1], c[2], nx, ny);
          }
          const auto& X = mesh.nodes;
          if (CalcTetSignedVolume(X[tet[0]], X[tet[1]], X[tet[2]], X[tet[3]]) < 0.0)
            std::swap(tet[0], tet[1]);
          mesh.tets.push_back(tet);
        }
  return mesh;
}

}  // namespace taut
