#include "plugin/box_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace taut {
namespace {

// Random boxes of very different sizes; every box holding a random point (or a box corner) is
// among the point's candidates, which come in ascending order.
TEST(BoxGridTest, CandidatesHoldEveryBoxContainingThePoint) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::AlignedBox3d> boxes;
  for (int b = 0; b < 500; ++b) {
    const Vec3 lo(unit(random), unit(random), unit(random));
    const double size = b % 50 == 0 ? 0.5 : 0.02 * unit(random);  // a few large ones
    boxes.emplace_back(lo, lo + size * Vec3(unit(random), unit(random), unit(random)));
  }
  boxes.emplace_back(Vec3(0.3, 0.3, 0.3), Vec3(0.3, 0.3, 0.3));  // a point
  const BoxGrid grid(boxes);
  std::vector<Vec3> queries = {boxes.back().min(), boxes[3].max(), boxes[4].min()};
  for (int q = 0; q < 2000; ++q) queries.emplace_back(unit(random), unit(random), unit(random));
  int hits = 0;
  for (const Vec3& p : queries) {
    const BoxGrid::Cell cell = grid.FindCandidates(p);
    const std::vector<int> candidates(cell.begin(), cell.end());
    EXPECT_TRUE(std::is_sorted(candidates.begin(), candidates.end()));
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      if (!boxes[b].contains(p)) continue;
      ++hits;
      EXPECT_TRUE(std::binary_search(candidates.begin(), candidates.end(), static_cast<int>(b)))
          << "box " << b << " holds (" << p.transpose() << ")";
    }
    EXPECT_LT(candidates.size(), boxes.size() / 4);  // a grid, not a list of everything
  }
  EXPECT_GT(hits, 100);
}

TEST(BoxGridTest, PointsOutsideTheBoundsHaveNoCandidatesAndBadBoxesAreRejected) {
  const BoxGrid grid({Eigen::AlignedBox3d(Vec3(0, 0, 0), Vec3(1, 1, 1)),
                      Eigen::AlignedBox3d(Vec3(2, 0, 0), Vec3(3, 1, 1))});
  EXPECT_EQ(grid.FindCandidates(Vec3(3.01, 0.5, 0.5)).begin(),
            grid.FindCandidates(Vec3(3.01, 0.5, 0.5)).end());
  EXPECT_EQ(grid.FindCandidates(Vec3(0.5, std::nan(""), 0.5)).begin(), nullptr);
  const BoxGrid::Cell corner = grid.FindCandidates(Vec3(3, 1, 1));  // on the max faces
  EXPECT_EQ(std::vector<int>(corner.begin(), corner.end()), std::vector<int>{1});
  using Boxes = std::vector<Eigen::AlignedBox3d>;
  EXPECT_THROW(BoxGrid(Boxes{}), InputError);
  EXPECT_THROW(BoxGrid(Boxes{Eigen::AlignedBox3d()}), InputError);  // an empty box
  // Far-apart tiny boxes: the grid stays small (cells grow) and still finds both.
  const BoxGrid sparse({Eigen::AlignedBox3d(Vec3(0, 0, 0), Vec3(1e-9, 1e-9, 1e-9)),
                        Eigen::AlignedBox3d(Vec3(1e6, 1e6, 1e6), Vec3(1e6, 1e6, 1e6))});
  EXPECT_NE(sparse.FindCandidates(Vec3(0, 0, 0)).begin(),
            sparse.FindCandidates(Vec3(0, 0, 0)).end());
  EXPECT_NE(sparse.FindCandidates(Vec3(1e6, 1e6, 1e6)).begin(),
            sparse.FindCandidates(Vec3(1e6, 1e6, 1e6)).end());
}

}  // namespace
}  // namespace taut
