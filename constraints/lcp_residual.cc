// Validation and residuals of the mixed complementarity problem (docs/math.md §5.4).
#include "constraints/lcp_residual.h"

#include <cmath>

namespace taut {

int AppendContactRows(double mu, FrictionCone cone, std::vector<PgsRow>* rows) {
  TAUT_DEMAND(rows != nullptr, "AppendContactRows: rows is null");
  const int n = static_cast<int>(rows->size());
  rows->push_back(MakeUnilateralRow());
  for (int k = 0; k < 2; ++k) {
    PgsRow t;
    t.kind = RowKind::kFriction;
    t.cone = cone;
    t.normal = n;
    t.partner = n + 2 - k;  // t1 = n + 1 pairs with n + 2 and back
    t.lo = -std::numeric_limits<double>::infinity();
    t.mu = mu;
    rows->push_back(t);
  }
  return n;
}

void ValidatePgsRows(const std::vector<PgsRow>& rows, int m) {
  TAUT_DEMAND(static_cast<int>(rows.size()) == m, "PGS problem: ", rows.size(), " rows for a ", m,
              " x ", m, " Delassus matrix");
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int c = 0; c < m; ++c) {
    const PgsRow& row = rows[c];
    switch (row.kind) {
      case RowKind::kUnilateral:
        TAUT_DEMAND(row.lo == 0.0 && row.hi == kInf, "PGS row ", c,
                    ": a unilateral row needs lo = 0 and hi = +inf, got [", row.lo, ", ", row.hi,
                    "]");
        break;
      case RowKind::kBilateral:
        TAUT_DEMAND(row.lo <= row.hi && row.lo < kInf && row.hi > -kInf, "PGS row ", c,
                    ": bilateral bounds [", row.lo, ", ", row.hi, "] are empty or NaN");
        break;
      case RowKind::kFriction: {
        TAUT_DEMAND(row.normal >= 0 && row.normal < m, "PGS row ", c, ": friction normal index ",
                    row.normal, " is outside [0, ", m, ")");
        TAUT_DEMAND(rows[row.normal].kind == RowKind::kUnilateral, "PGS row ", c,
                    ": friction normal row ", row.normal, " is not unilateral");
        TAUT_DEMAND(std::isfinite(row.mu) && row.mu >= 0.0, "PGS row ", c,
                    ": friction coefficient mu = ", row.mu, " must be finite and >= 0");
        if (row.partner == -1) break;
        TAUT_DEMAND(row.partner >= 0 && row.partner < m && row.partner != c, "PGS row ", c,
                    ": friction partner index ", row.partner, " is invalid");
        const PgsRow& other = rows[row.partner];
        TAUT_DEMAND(other.kind == RowKind::kFriction && other.partner == c &&
                        other.normal == row.normal && other.mu == row.mu && other.cone == row.cone,
                    "PGS row ", c, ": friction partner ", row.partner,
                    " does not pair back with the same normal, mu and cone");
        break;
      }
      default:
        TAUT_DEMAND(false, "PGS row ", c, ": unknown row kind ", static_cast<int>(row.kind));
    }
  }
}

void ValidateLcpProblem(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                        const Eigen::Ref<const VecX>& lambda) {
  const Eigen::Index m = W.rows();
  TAUT_DEMAND(W.cols() == m, "PGS problem: W is ", W.rows(), " x ", W.cols(), ", not square");
  TAUT_DEMAND(q.size() == m && lambda.size() == m, "PGS problem: W is ", m, " x ", m, " but q has ",
              q.size(), " and lambda ", lambda.size(), " entries");
  ValidatePgsRows(rows, static_cast<int>(m));
  double scale = 0.0;
  for (Eigen::Index j = 0; j < m; ++j) {
    TAUT_DEMAND(std::isfinite(q[j]) && std::isfinite(lambda[j]), "PGS problem: q[", j, "] = ", q[j],
                " or lambda[", j, "] = ", lambda[j], " is not finite");
    for (Eigen::Index i = 0; i < m; ++i) {
      TAUT_DEMAND(std::isfinite(W(i, j)), "PGS problem: W(", i, ", ", j, ") = ", W(i, j));
      scale = std::max(scale, std::abs(W(i, j)));
    }
  }
  // Symmetry: |W_ij - W_ji| <= 1e-9 max|W| (W = J Y is symmetric up to rounding).
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = j + 1; i < m; ++i) {
      TAUT_DEMAND(std::abs(W(i, j) - W(j, i)) <= 1e-9 * scale,
                  "PGS problem: W is not symmetric: W(", i, ", ", j, ") = ", W(i, j), " but W(", j,
                  ", ", i, ") = ", W(j, i));
    }
  }
}

namespace internal {

LcpResidual CalcLcpResidualUnchecked(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                                     const Eigen::Ref<const VecX>& lambda) {
  LcpResidual res;
  const int m = static_cast<int>(rows.size());
  // w_c = q_c + (W lambda)_c, column c by symmetry (contiguous in column-major storage).
  auto calc_w = [&](int c) { return q[c] + W.col(c).dot(lambda); };
  for (int c = 0; c < m; ++c) {
    const PgsRow& row = rows[c];
    const double w = calc_w(c);
    if (row.kind != RowKind::kFriction) {
      // Box row: r_c = lambda_c - clamp(lambda_c - w_c, lo, hi).
      const double r = lambda[c] - ClampToBox(lambda[c] - w, row.lo, row.hi);
      res.natural_map = std::max(res.natural_map, std::abs(r));
      if (row.kind == RowKind::kUnilateral) {
        res.complementarity = std::max(res.complementarity, std::abs(lambda[c] * w));
        res.min_unilateral_w = std::min(res.min_unilateral_w, w);
      }
      continue;
    }
    const double radius = CalcCoulombRadius(row.mu, lambda[row.normal]);
    if (row.cone == FrictionCone::kBox || row.partner == -1) {
      // Box cone or single tangential row: the interval [-mu lambda_n, mu lambda_n].
      const double r = lambda[c] - ClampToBox(lambda[c] - w, -radius, radius);
      res.natural_map = std::max(res.natural_map, std::abs(r));
    } else if (c < row.partner) {
      // Disk pair, measured once at its first row: r_t = lambda_t - Proj_disk(lambda_t - w_t).
      const int p = row.partner;
      const Eigen::Vector2d proj =
          ProjectOnCoulombDisk(lambda[c] - w, lambda[p] - calc_w(p), row.mu, lambda[row.normal]);
      res.natural_map =
          std::max({res.natural_map, std::abs(lambda[c] - proj[0]), std::abs(lambda[p] - proj[1])});
    }
  }
  res.max_violation = std::max(0.0, -res.min_unilateral_w);
  return res;
}

}  // namespace internal

LcpResidual CalcLcpResidual(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                            const Eigen::Ref<const VecX>& lambda) {
  ValidateLcpProblem(W, q, rows, lambda);
  return internal::CalcLcpResidualUnchecked(W, q, rows, lambda);
}

double CalcLcpObjective(const MatX& W, const VecX& q, const Eigen::Ref<const VecX>& lambda) {
  TAUT_DEMAND(W.rows() == W.cols() && W.rows() == q.size() && q.size() == lambda.size(),
              "CalcLcpObjective: sizes W ", W.rows(), " x ", W.cols(), ", q ", q.size(),
              ", lambda ", lambda.size(), " do not match");
  // 1/2 lambda^T W lambda + q^T lambda, column by column (no temporary vector).
  double f = 0.0;
  for (Eigen::Index c = 0; c < W.cols(); ++c) {
    f += lambda[c] * (0.5 * W.col(c).dot(lambda) + q[c]);
  }
  return f;
}

}  // namespace taut
