// The row curvature G = h sum_c lambda_c [-d^2 C_c/dx^2]_+ of the primal path's Newton matrix
// (docs/math.md §5.9), as the row sources emit it: element blocks (3k x 3k over one element's
// nodes) and single node-pair blocks.
#pragma once

#include <array>
#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/island_rows.h"

namespace taut {

class CurvatureMetric final : public CurvatureSink {
 public:
  void AddBlock(int body, int node_a, int node_b, const Mat3& block) override;
  void AddElementBlock(int body, int element, const int* nodes,
                       const Eigen::Ref<const MatX>& block) override;

  // Stage: G = h sum_c lambda_c [-d^2 C_c/dx^2]_+ over the limit rows with lambda_c > 0, from the
  // sources, at the rows (collected at velocities v); replaces what was held.
  void CollectLimitRows(double h, const std::vector<IslandBody*>& bodies,
                        const std::vector<ConstraintSource*>& sources, const IslandRows& rows,
                        const VecX& lambda, const std::vector<VecX>& v);
  void Clear();
  // Replaces each element block that is not positive definite by its positive semi-definite part
  // (the sources may keep mildly negative modes, strain_frame_curvature.h); returns how many.
  int ClampIndefiniteElementBlocks();
  bool empty() const { return node_blocks_.empty() && elements_.empty(); }
  // out_b += G_b u_b for every body b.
  void AddTimes(const std::vector<VecX>& u, std::vector<VecX>& out) const;
  // H_b += G_b: element blocks through the element's value map, node blocks one by one.
  void AddToNewtonMatrices(const std::vector<IslandBody*>& bodies) const;

 private:
  struct NodeBlock {
    int body, a, b;
    Mat3 block;
  };
  struct ElementBlock {
    int body, element, num_nodes;
    std::array<int, kMaxRowNodes> nodes;
    size_t offset;  // of the 3k x 3k column-major block in values_
  };
  // The element block e as a matrix over its values.
  Eigen::Map<const MatX> Block(const ElementBlock& e) const;

  std::vector<NodeBlock> node_blocks_;
  std::vector<ElementBlock> elements_;
  std::vector<double> values_;
  VecX weights_;  // h lambda_c of the rows, for the sources (reused across calls)
};

}  // namespace taut
