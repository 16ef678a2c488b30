// Scatter of an element's curvature matrix into a CurvatureSink (constraints/constraint_row.h),
// shared by the strain- and energy-limit sources.
#pragma once

#include "constraints/constraint_row.h"
#include "plugin/element_model.h"

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

// The same for an element matrix of run-time size, N = H.rows() / 3 nodes.
inline void AddElementCurvatureBlocks(const ElementMatrix& H, double weight, int body,
                                      const int* nodes, CurvatureSink& sink) {
  const int num_nodes = static_cast<int>(H.rows() / 3);
  for (int a = 0; a < num_nodes; ++a)
    for (int b = 0; b < num_nodes; ++b)
      sink.AddBlock(body, nodes[a], nodes[b], weight * H.block<3, 3>(3 * a, 3 * b));
}

}  // namespace taut
