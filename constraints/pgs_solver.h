// Projected Gauss-Seidel for the mixed complementarity problem of lcp_residual.h
// (docs/math.md §5.6).
//
// Box rows (unilateral, bilateral, box-cone friction) get the scalar update
//   lambda_c <- clamp(lambda_c - omega w_c / W_cc, lo_c, hi_c),   w_c = q_c + (W lambda)_c.
// A disk-cone friction pair (t1, t2) is updated as one 2x2 block: the exact minimizer of the
// pair's quadratic over the Coulomb disk ||lambda_t|| <= mu lambda_n (SolveCoulombDiskBlock), then
// relaxed and projected back onto the disk. Row-wise updates with a plain disk projection would
// stop at a point where lambda_t is not opposite to the slip unless W_tt is a multiple of I.
// The inline functions below are the whole per-row kernel, so a matrix-free variant that forms
// w_c from J and Y = A^-1 J^T can reuse them unchanged.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "constraints/lcp_residual.h"
#include "plugin/common.h"

namespace taut {

// Controls of SolvePgs. Checked on every call (cheap).
struct PgsSettings {
  int max_sweeps = 50;              // sweeps over all rows, >= 0
  double tolerance = 1e-6;          // stop when max_c W_cc |Delta lambda_c| of a sweep (the largest
                                    // change of a row's own w, units of w) is <= tolerance; >= 0
  double residual_tolerance = 0.0;  // also stop when the natural-map residual (units of lambda and
                                    // w, see lcp_residual.h) is <= this; 0 = off (saves one W
                                    // lambda product per sweep); >= 0
  double relaxation = 1.0;          // SOR factor omega in (0, 2); 1 = plain Gauss-Seidel
  double min_diagonal = 1e-10;  // rows with W_cc <= min_diagonal * max_d W_dd are skipped (their
                                // lambda is set to the point of their set nearest 0); in [0, 1)
  bool validate_input = true;   // check W, q, rows, lambda (O(m^2)); off for trusted callers
  VecX* w_workspace = nullptr;  // when set, w = W lambda + q is kept current in it: a sweep then
                                // costs O(m) per changed row instead of O(m) per row
};

// Throws InputError naming the field unless every field of `s` is in its documented range.
void ValidatePgsSettings(const PgsSettings& s);

// What a SolvePgs call did.
struct PgsStats {
  int sweeps = 0;            // sweeps run
  double final_delta = 0.0;  // max_c W_cc |Delta lambda_c| in the last sweep
  int skipped_rows = 0;      // rows with W_cc below the min_diagonal threshold
  double residual = 0.0;     // natural-map residual ||lambda - Proj_K(lambda - w)||_inf at exit
  bool converged = false;    // a tolerance was met (also true for m = 0)
};

// Box-row update clamp(lambda_c - omega w_c / W_cc, lo, hi); W_cc > 0 (docs/math.md §5.6).
inline double CalcBoxRowUpdate(double lambda_c, double w_c, double W_cc, double lo, double hi,
                               double omega) {
  return ClampToBox(lambda_c - omega * w_c / W_cc, lo, hi);
}

// argmin over ||x|| <= radius of 1/2 x^T B x + g^T x for symmetric PSD 2x2 B: the exact block
// update of a friction pair with g = w_t - B lambda_t. Interior: B x = -g. Boundary:
// x = -(B + nu I)^-1 g with ||x|| = radius, nu > 0 by Newton on 1/||x(nu)|| - 1/radius (concave,
// so iterates from the left never overshoot; Moré & Sorensen 1983).
inline Eigen::Vector2d SolveCoulombDiskBlock(const Eigen::Matrix2d& B, const Eigen::Vector2d& g,
                                             double radius) {
  if (!(radius > 0.0)) return Eigen::Vector2d::Zero();
  // B = e_0 v_0 v_0^T + e_1 v_1 v_1^T in closed form, e_0 <= e_1.
  const double off = 0.5 * (B(0, 1) + B(1, 0));
  const double mean = 0.5 * (B(0, 0) + B(1, 1));
  const double spread = std::hypot(0.5 * (B(0, 0) - B(1, 1)), off);
  const double theta = 0.5 * std::atan2(2.0 * off, B(0, 0) - B(1, 1));
  const Eigen::Vector2d v[2] = {Eigen::Vector2d(-std::sin(theta), std::cos(theta)),
                                Eigen::Vector2d(std::cos(theta), std::sin(theta))};
  const double e_max = std::max(mean + spread, 0.0);
  double e[2] = {std::max(mean - spread, 0.0), e_max};
  if (e[0] <= 1e-13 * e_max) e[0] = 0.0;
  const double h[2] = {v[0].dot(g), v[1].dot(g)};
  // Interior candidate x = -B^+ g (a zero eigenvalue with h != 0 means unbounded: boundary).
  bool bounded = true;
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    if (h[i] == 0.0) continue;
    if (e[i] == 0.0)
      bounded = false;
    else
      x -= (h[i] / e[i]) * v[i];
  }
  if (bounded && x.norm() <= radius) return x;
  // Boundary: the root nu of ||x(nu)|| = radius lies right of max_i(|h_i| / radius - e_i).
  double nu = 0.0;
  for (int i = 0; i < 2; ++i) {
    if (h[i] != 0.0) nu = std::max(nu, std::abs(h[i]) / radius - e[i]);
  }
  for (int iter = 0; iter < 60; ++iter) {
    double s2 = 0.0, s3 = 0.0;  // sum h_i^2 / (e_i + nu)^2 and ^3
    for (int i = 0; i < 2; ++i) {
      if (h[i] == 0.0) continue;
      const double inv = 1.0 / (e[i] + nu);
      s2 += h[i] * h[i] * inv * inv;
      s3 += h[i] * h[i] * inv * inv * inv;
    }
    const double norm = std::sqrt(s2);
    const double phi = 1.0 / norm - 1.0 / radius;  // < 0 while ||x|| > radius
    if (phi >= -1e-15 / radius) break;
    nu -= phi * norm * s2 / s3;  // Newton: phi' = s3 / norm^3
  }
  x.setZero();
  for (int i = 0; i < 2; ++i) {
    if (h[i] != 0.0) x -= (h[i] / (e[i] + nu)) * v[i];
  }
  const double norm = x.norm();
  return norm > radius ? Eigen::Vector2d(x * (radius / norm)) : x;
}

// Solves the problem of lcp_residual.h by projected Gauss-Seidel, rows in index order (a disk
// friction pair at its first row). lambda is the warm start on entry and the solution on exit.
// Validates W (square, finite, symmetric), q, lambda, rows and settings; throws InputError.
// Allocates no heap memory.
PgsStats SolvePgs(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                  Eigen::Ref<VecX> lambda, const PgsSettings& settings);

}  // namespace taut
