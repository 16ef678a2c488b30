// Scatter of an element's curvature matrix into a CurvatureSink (constraints/constraint_row.h),
// shared by the strain- and energy-limit sources.
#pragma once

#include "constraints/constraint_row.h"

namespace taut {

// sink(body; nodes[a], nodes[b]) += weight * H(3a..3a+2, 3b..3b+2) for every ordered node pair
// (a, b) of the element, the diagonal a = b included. H: (3N x 3N), node-major xyz.
template <int N>
void AddElementCurvatureBlocks(const Eigen::Matrix<double, 3 * N, 3 * N>& H, double weight,
                               int body, const int* nodes, CurvatureSink& sink) {
  for (int a = 0; a < N; ++a)
    for (int b = 0; b < N; ++b)
      sink.AddBlock(body, nodes[a], nodes[b], weight * H.template block<3, 3>(3 * a, 3 * b));
}

}  // namespace taut
