// Error of a run against a reference run and the small statistics taut-report prints.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "plugin/common.h"

namespace taut {

// Positions of the free nodes of every body of a scene at one sample time: (num_bodies) flat
// vectors of 3 x (free nodes of the body) coordinates [m].
using TrajectorySample = std::vector<VecX>;

// Length of the diagonal of the axis-aligned bounding box of flat 3N positions [m].
inline double CalcBoundingBoxDiagonal(const VecX& positions) {
  TAUT_DEMAND(positions.size() >= 3 && positions.size() % 3 == 0,
              "CalcBoundingBoxDiagonal: ", positions.size(), " coordinates is not 3N with N >= 1");
  const Eigen::Map<const Eigen::Matrix3Xd> nodes(positions.data(), 3, positions.size() / 3);
  return (nodes.rowwise().maxCoeff() - nodes.rowwise().minCoeff()).norm();
}

// Whether two samples have the same bodies with the same free-node counts (a scene that swaps
// bodies during a run can differ from its reference at some sample times).
inline bool HaveSameLayout(const TrajectorySample& a, const TrajectorySample& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size()) return false;
  return true;
}

// Normalized RMS distance of one sample to its reference:
//   e = sqrt( sum_b sum_i |x_bi - x_ref_bi|^2 / L_b^2 / sum_b N_b ),
// i over the N_b sampled nodes of body b, L_b its characteristic length (bounding-box diagonal).
// Throws InputError when the body counts, node counts or lengths do not match.
inline double CalcNormalizedRmsDistance(const TrajectorySample& x, const TrajectorySample& x_ref,
                                        const std::vector<double>& lengths) {
  TAUT_DEMAND(x.size() == x_ref.size() && x.size() == lengths.size(),
              "CalcNormalizedRmsDistance: ", x.size(), " bodies, ", x_ref.size(),
              " reference bodies and ", lengths.size(), " lengths differ");
  double sum = 0.0;
  Eigen::Index nodes = 0;
  for (size_t b = 0; b < x.size(); ++b) {
    TAUT_DEMAND(x[b].size() == x_ref[b].size() && x[b].size() % 3 == 0,
                "CalcNormalizedRmsDistance: body ", b, " has ", x[b].size(),
                " coordinates, its reference ", x_ref[b].size());
    TAUT_DEMAND(lengths[b] > 0.0, "CalcNormalizedRmsDistance: body ", b, " has length ", lengths[b],
                " (must be > 0)");
    sum += (x[b] - x_ref[b]).squaredNorm() / (lengths[b] * lengths[b]);
    nodes += x[b].size() / 3;
  }
  return nodes > 0 ? std::sqrt(sum / static_cast<double>(nodes)) : 0.0;
}

// Root mean square of the values (NaN for none).
inline double CalcRms(const std::vector<double>& values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

// Median of the values (mean of the middle two for an even count; NaN for none).
inline double CalcMedian(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

}  // namespace taut
