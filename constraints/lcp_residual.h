// The mixed complementarity problem solved by PGS (docs/math.md §5.4) and its residuals.
//
// Problem: find lambda with w = W lambda + q, W = J A^-1 J^T (m x m, symmetric PSD), and per row c
//   box row (kUnilateral, kBilateral):  lambda_c in [lo_c, hi_c] and
//       lambda_c = lo_c => w_c >= 0,  lambda_c = hi_c => w_c <= 0,  lo_c < lambda_c < hi_c => w_c =
//       0; a unilateral row is the box [0, +inf): 0 <= lambda_c  complementary to  w_c >= 0.
//   friction pair (t1, t2) of normal row n, disk cone:  ||lambda_t|| <= mu lambda_n and
//       lambda_t = -mu lambda_n w_t / ||w_t|| when w_t != 0 (Coulomb, maximal dissipation);
//   box cone: each tangential row is a box row with bounds [-mu lambda_n, mu lambda_n].
// Equivalently lambda = Proj_K(lambda - w) (natural map), which is what CalcLcpResidual measures.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "plugin/common.h"

namespace taut {

// What a constraint row enforces (see the file comment).
enum class RowKind : std::uint8_t {
  kUnilateral,  // lambda >= 0 complementary to w >= 0 (lo = 0, hi = +inf)
  kBilateral,   // w = 0 while lo < lambda < hi (joints, attachments; lo = -inf, hi = +inf by
                // default)
  kFriction,    // tangential row of the contact whose normal row is `normal`
};

// Shape of the friction set of one contact.
enum class FrictionCone : std::uint8_t {
  kDisk,  // ||(lambda_t1, lambda_t2)|| <= mu lambda_n (Coulomb; docs/math.md §5.4)
  kBox,   // |lambda_t1|, |lambda_t2| <= mu lambda_n each (lets ||lambda_t|| reach sqrt(2) mu
          // lambda_n)
};

// One row of the problem: 40-byte POD kept in a contiguous array, walked in index order.
struct PgsRow {
  RowKind kind = RowKind::kUnilateral;
  FrictionCone cone = FrictionCone::kDisk;  // friction rows only
  std::int32_t normal = -1;   // friction rows: index of the contact's kUnilateral normal row
  std::int32_t partner = -1;  // friction rows: the other tangential row of the pair, -1 if single
  double lo = 0.0;            // box rows: lower bound of lambda (unilateral: exactly 0)
  double hi = std::numeric_limits<double>::infinity();  // box rows: upper bound (unilateral: +inf)
  double mu = 0.0;  // friction rows: Coulomb coefficient, >= 0, same on both rows
};
static_assert(sizeof(PgsRow) == 40 && std::is_trivially_copyable<PgsRow>::value,
              "PgsRow is a compact POD row");

// A unilateral row: 0 <= lambda complementary to w >= 0.
inline PgsRow MakeUnilateralRow() { return PgsRow{}; }

// A bilateral row with bounds lo <= lambda <= hi (w = 0 while lambda is strictly inside).
inline PgsRow MakeBilateralRow(double lo = -std::numeric_limits<double>::infinity(),
                               double hi = std::numeric_limits<double>::infinity()) {
  PgsRow row;
  row.kind = RowKind::kBilateral;
  row.lo = lo;
  row.hi = hi;
  return row;
}

// Appends the rows (n, t1, t2) of one frictional contact and returns the index of n.
int AppendContactRows(double mu, FrictionCone cone, std::vector<PgsRow>* rows);

// Clamps x to [lo, hi].
inline double ClampToBox(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

// Radius mu max(lambda_n, 0) of the Coulomb disk of a contact (a negative normal gives no
// friction).
inline double CalcCoulombRadius(double mu, double lambda_n) { return mu * std::max(lambda_n, 0.0); }

// Euclidean projection of (lambda_t1, lambda_t2) onto the disk ||lambda_t|| <= mu max(lambda_n, 0).
inline Eigen::Vector2d ProjectOnCoulombDisk(double lambda_t1, double lambda_t2, double mu,
                                            double lambda_n) {
  const double radius = CalcCoulombRadius(mu, lambda_n);
  const double norm = std::hypot(lambda_t1, lambda_t2);
  if (norm <= radius) return Eigen::Vector2d(lambda_t1, lambda_t2);
  const double scale = radius / norm;  // norm > radius >= 0
  return Eigen::Vector2d(scale * lambda_t1, scale * lambda_t2);
}

// Residual measures of a candidate lambda (w = W lambda + q).
struct LcpResidual {
  double natural_map = 0.0;      // ||lambda - Proj_K(lambda - w)||_inf over all rows (0 iff solved)
  double complementarity = 0.0;  // max over unilateral rows of |lambda_c w_c|
  double max_violation = 0.0;    // max(0, -min over unilateral rows of w_c)
  double min_unilateral_w = std::numeric_limits<double>::infinity();  // min w_c, unilateral rows
};

// Throws InputError unless rows describe a valid problem of size m (bounds, friction pairing, mu).
void ValidatePgsRows(const std::vector<PgsRow>& rows, int m);

// Throws InputError unless W is m x m, finite and symmetric (relative 1e-9), q and lambda have
// size m and are finite, and rows are valid.
void ValidateLcpProblem(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                        const Eigen::Ref<const VecX>& lambda);

// Natural-map residual, complementarity gap and violation of lambda (validates the problem).
LcpResidual CalcLcpResidual(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                            const Eigen::Ref<const VecX>& lambda);

// Objective 1/2 lambda^T W lambda + q^T lambda that PGS lowers row by row for box rows.
double CalcLcpObjective(const MatX& W, const VecX& q, const Eigen::Ref<const VecX>& lambda);

namespace internal {
// CalcLcpResidual without validation and without heap allocation (used inside SolvePgs).
LcpResidual CalcLcpResidualUnchecked(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                                     const Eigen::Ref<const VecX>& lambda);
}  // namespace internal

}  // namespace taut
