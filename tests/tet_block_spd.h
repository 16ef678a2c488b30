// A random SPD matrix with the 3x3-block pattern of a box tet mesh, for the factorization tests
// and benchmarks.
#pragma once

#include <Eigen/SparseCore>
#include <random>
#include <vector>

#include "plugin/box_tet_mesher.h"

namespace taut {
namespace testing {

// M + K on an nx x ny x nz-cell unit box tet mesh: K sums random PSD 12x12 element matrices
// B^T B (entries of B uniform in [-1, 1]), M is a random diagonal uniform in [0.1, 1.1]. Full
// symmetric CSC, compressed, SPD.
inline Eigen::SparseMatrix<double> MakeRandomTetBlockSpd(int nx, int ny, int nz, unsigned seed) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), nx, ny, nz);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 3 * static_cast<int>(mesh.nodes.size());
  std::vector<Eigen::Triplet<double>> t;
  for (const auto& tet : mesh.tets) {
    const Mat12 B = Mat12::NullaryExpr([&] { return u(rng); });
    const Mat12 K_e = B.transpose() * B;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            t.emplace_back(3 * tet[a] + r, 3 * tet[b] + c, K_e(3 * a + r, 3 * b + c));
  }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 0.1 + 0.5 * (1.0 + u(rng)));
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

}  // namespace testing
}  // namespace taut
