#include "plugin/box_grid.h"

#include <algorithm>
#include <cmath>

namespace taut {
namespace {

// Cells per axis for the given edge, in [1, 2^20] each.
std::array<int, 3> CalcGridDims(const Vec3& extent, double edge) {
  std::array<int, 3> dims;
  for (int d = 0; d < 3; ++d)
    dims[d] = static_cast<int>(std::clamp(std::ceil(extent[d] / edge), 1.0, 1048576.0));
  return dims;
}

long long CountCells(const std::array<int, 3>& dims) {
  return static_cast<long long>(dims[0]) * dims[1] * dims[2];
}

}  // namespace

BoxGrid::BoxGrid(const std::vector<Eigen::AlignedBox3d>& boxes) {
  TAUT_DEMAND(!boxes.empty(), "BoxGrid: no boxes to bin");
  Eigen::AlignedBox3d bounds;
  double edge_sum = 0.0;
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const Eigen::AlignedBox3d& box = boxes[b];
    TAUT_DEMAND(!box.isEmpty() && box.min().allFinite() && box.max().allFinite(), "BoxGrid: box ",
                b, " is empty or not finite");
    bounds.extend(box);
    edge_sum += box.sizes().maxCoeff();
  }
  const Vec3 extent = bounds.sizes();
  // Mean box size; boxes of zero size (points) fall back to the bounds.
  edge_ = edge_sum / static_cast<double>(boxes.size());
  if (!(edge_ > 0.0)) edge_ = std::max(extent.maxCoeff(), 1.0);
  const long long max_cells = 8 * static_cast<long long>(boxes.size()) + 64;
  dims_ = CalcGridDims(extent, edge_);
  while (CountCells(dims_) > max_cells) {
    edge_ *=
        std::cbrt(static_cast<double>(CountCells(dims_)) / static_cast<double>(max_cells)) * 1.01;
    dims_ = CalcGridDims(extent, edge_);
  }
  origin_ = bounds.min();
  max_ = bounds.max();
  // Two passes (count, then fill) give each cell its boxes in ascending order.
  const int num_cells = static_cast<int>(CountCells(dims_));
  cell_start_.assign(num_cells + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const std::array<long long, 3> lo = CalcCellCoordinates(boxes[b].min());
      const std::array<long long, 3> hi = CalcCellCoordinates(boxes[b].max());
      for (long long k = std::max(lo[2], 0LL); k <= std::min<long long>(hi[2], dims_[2] - 1); ++k)
        for (long long j = std::max(lo[1], 0LL); j <= std::min<long long>(hi[1], dims_[1] - 1); ++j)
          for (long long i = std::max(lo[0], 0LL); i <= std::min<long long>(hi[0], dims_[0] - 1);
               ++i) {
            const int cell =
                CalcCellIndex(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k));
            if (pass == 0) {
              ++cell_start_[cell + 1];
            } else {
              box_of_entry_[fill[cell]++] = static_cast<int>(b);
            }
          }
    }
    if (pass == 0) {
      for (int c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
      box_of_entry_.resize(cell_start_.back());
    }
  }
}

std::array<long long, 3> BoxGrid::CalcCellCoordinates(const Vec3& p) const {
  // floor is monotone in p, so a point inside a closed box maps into the box's cell range.
  std::array<long long, 3> ijk;
  for (int d = 0; d < 3; ++d) {
    const double q = std::floor((p[d] - origin_[d]) / edge_);
    ijk[d] = static_cast<long long>(std::clamp(q, -1.0, static_cast<double>(dims_[d])));
  }
  return ijk;
}

BoxGrid::Cell BoxGrid::FindCandidates(const Vec3& p) const {
  if (!p.allFinite() || (p.array() < origin_.array()).any() || (p.array() > max_.array()).any())
    return {};
  // Points on the grid's max faces belong to its last cells.
  std::array<long long, 3> ijk = CalcCellCoordinates(p);
  for (int d = 0; d < 3; ++d) ijk[d] = std::clamp<long long>(ijk[d], 0, dims_[d] - 1);
  const int cell =
      CalcCellIndex(static_cast<int>(ijk[0]), static_cast<int>(ijk[1]), static_cast<int>(ijk[2]));
  const int* entries = box_of_entry_.data();
  return {entries + cell_start_[cell], entries + cell_start_[cell + 1]};
}

}  // namespace taut
