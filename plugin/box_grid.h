// A uniform grid binning axis-aligned boxes, to find the boxes that may hold a point without
// testing every box (the broad phase of point location in a mesh).
#pragma once

#include <array>
#include <vector>

#include "plugin/common.h"

namespace taut {

class BoxGrid {
 public:
  // The indices of the boxes binned in one cell, ascending.
  struct Cell {
    const int* first = nullptr;
    const int* last = nullptr;
    const int* begin() const { return first; }
    const int* end() const { return last; }
  };

  // Bins box i into every cell it overlaps. The cell edge is the mean longest edge of the boxes,
  // enlarged when needed so the grid has at most 8 num_boxes + 64 cells. Throws InputError when
  // there are no boxes or a box is empty or not finite.
  explicit BoxGrid(const std::vector<Eigen::AlignedBox3d>& boxes);

  // The boxes binned in the cell holding p: every box that contains p is among them (and boxes
  // near p). Empty when p is outside the bounds of all boxes.
  Cell FindCandidates(const Vec3& p) const;

 private:
  // Cell index along each axis of p, unclamped: floor((p - origin) / edge).
  std::array<long long, 3> CalcCellCoordinates(const Vec3& p) const;
  int CalcCellIndex(int i, int j, int k) const { return i + dims_[0] * (j + dims_[1] * k); }

  Vec3 origin_ = Vec3::Zero();     // min corner of the bounds of all boxes
  Vec3 max_ = Vec3::Zero();        // max corner of those bounds
  double edge_ = 1.0;              // cell edge [m]
  std::array<int, 3> dims_{};      // cells per axis
  std::vector<int> cell_start_;    // (num_cells + 1) offsets into box_of_entry_
  std::vector<int> box_of_entry_;  // box indices, cell by cell
};

}  // namespace taut
