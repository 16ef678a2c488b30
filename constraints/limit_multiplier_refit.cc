#include "constraints/limit_multiplier_refit.h"

#include <algorithm>
#include <cmath>

namespace taut {

namespace {
bool IsRefitRow(const ConstraintRow& row) {
  return IsLimitRow(row) && !row.bilateral && row.friction_of == 0;
}
}  // namespace

void RefitLimitMultipliers(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                           const std::vector<VecX>& a_dv, double violation_tolerance,
                           double target_stationarity, int max_sweeps, VecX& lambda) {
  // Residual r = A (v - v*) - J^T lambda on free blocks (pinned blocks carry reactions).
  const size_t nb = bodies.size();
  std::vector<VecX> r(a_dv.begin(), a_dv.begin() + nb);
  double momentum = 0.0;  // ||A (v - v*)||^2 on free blocks
  for (size_t b = 0; b < nb; ++b) {
    for (int i = 0; i < bodies[b]->num_blocks(); ++i)
      if (bodies[b]->is_free_block(i))
        momentum += r[b].segment<3>(3 * i).squaredNorm();
      else
        r[b].segment<3>(3 * i).setZero();
  }
  // The active rows' free entries, flat: entry k of row a is entries[start[a] + k].
  struct Entry {
    int body, offset;
    Vec3 J;
  };
  std::vector<Entry> entries;
  std::vector<int> active, start;
  std::vector<double> diagonal;  // ||J_c||^2 over free blocks: the diagonal of J_a J_a^T
  for (int c = 0; c < rows.size(); ++c) {
    const ConstraintRow& row = rows[c];
    const bool refit = IsRefitRow(row);
    if (refit && row.C > violation_tolerance) lambda[c] = 0.0;  // slack: released
    if (refit && row.C <= violation_tolerance) {
      active.push_back(c);
      start.push_back(static_cast<int>(entries.size()));
      double norm = 0.0;
      row.ForEachEntry([&](int body, int block, const Vec3& J) {
        if (!bodies[body]->is_free_block(block)) return;
        entries.push_back({body, 3 * block, J});
        norm += J.squaredNorm();
      });
      diagonal.push_back(norm);
    }
    if (lambda[c] == 0.0) continue;
    row.ForEachEntry([&](int body, int block, const Vec3& J) {
      if (bodies[body]->is_free_block(block)) r[body].segment<3>(3 * block) -= lambda[c] * J;
    });
  }
  start.push_back(static_cast<int>(entries.size()));
  double residual = 0.0;  // ||r||^2, kept up to date by each coordinate step
  for (size_t b = 0; b < nb; ++b) residual += r[b].squaredNorm();
  // Stationarity is ||r|| over max(||J^T lambda||, ||A (v - v*)||) >= ||r|| / ||A (v - v*)||.
  const double target = target_stationarity * target_stationarity * momentum;
  // A refit whose residual, falling at its last sweep's rate over the sweeps left, would still be
  // above (2 target_stationarity)^2 ||A (v - v*)||^2 cannot certify: stop (a stall).
  const double give_up = 16.0 * target;
  for (int sweep = 0; sweep < max_sweeps && residual > target; ++sweep) {
    const double residual_before = residual;
    double largest_change = 0.0;
    for (size_t a = 0; a < active.size(); ++a) {
      if (!(diagonal[a] > 0.0)) continue;
      const int c = active[a];
      // lambda_c <- max(0, lambda_c + J_c . r / ||J_c||^2): the exact minimizer along lambda_c.
      double jr = 0.0;
      for (int k = start[a]; k < start[a + 1]; ++k)
        jr += entries[k].J.dot(r[entries[k].body].segment<3>(entries[k].offset));
      const double next = std::max(0.0, lambda[c] + jr / diagonal[a]);
      const double change = next - lambda[c];
      if (change == 0.0) continue;
      lambda[c] = next;
      for (int k = start[a]; k < start[a + 1]; ++k)
        r[entries[k].body].segment<3>(entries[k].offset) -= change * entries[k].J;
      // ||r - change J||^2 = ||r||^2 - 2 change J.r + change^2 ||J||^2.
      residual += change * (change * diagonal[a] - 2.0 * jr);
      largest_change = std::max(largest_change, std::abs(change));
    }
    const double scale = lambda.size() > 0 ? lambda.cwiseAbs().maxCoeff() : 0.0;
    if (largest_change <= 1e-9 * scale) break;
    const double rate = residual_before > 0.0 ? residual / residual_before : 0.0;
    if (give_up > 0.0 && residual * std::pow(rate, max_sweeps - sweep - 1) > give_up) break;
  }
}

}  // namespace taut
