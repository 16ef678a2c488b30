// Strain-limit constraint rows of one tet: C(x) >= 0 and its exact Jacobian dC/dx (paper A
// eqs. 11-18 and 19-22; docs/math.md §2-§3).
//
// With the signed SVD G = U diag(s) V^T, the limit frame Q and V' = Q^T V (w = V' e_i, so
// w_j = V'_ji), every row is scaled to C = 1 - |s_i - 1| / d_eff: C = 1 at rest, 0 at the limit,
// where d_eff is the limit deviation projected onto principal direction i:
//   hyperbolic (j,i):  C = 1 - kappa^j |V'_ji| |s_i - 1|              (d_eff = d^j / |V'_ji|)
//   ellipsoid (i):     C = 1 - |s_i - 1| ||K V' e_i||,  K = diag(kappa^j)  (d_eff = 1/||K w||)
//   linear interp (i): C = 1 - |s_i - 1| / |L - 1|,  L = ||diag(s^j) V' e_i||  (eqs. 21-22)
//   orthogonal (j,i):  C = |V'_ji| - |s_i - 1| / |d^j|   (eqs. 19-20 divided by |d^j|; here
//                      d_eff = d^j |V'_ji| vanishes on orthogonal pairs, so it cannot divide)
//   floor (i):         C = (s_i - s_floor) / (1 - s_floor)   (non-inversion, docs/math.md §3.8)
// with kappa^j, d^j from the bound's side (max: s_i > 1, min: s_i < 1). OP and LI use the capped
// deviations of StrainLimitParams. Only rows with C < tau are emitted, C_max only where s_i > 1
// and C_min only where s_i < 1 (docs/math.md §2 R2); the others hold with margin. sgn(0) := 0 at
// the |V'_ji| kink, which lies strictly inside the feasible set for the hyperbolic rows (R2).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "constraints/strain_limits.h"
#include "constraints/svd_derivatives.h"
#include "plugin/common.h"
#include "plugin/signed_svd.h"

namespace taut {

enum class StrainBound : std::uint8_t { kMin = 0, kMax = 1 };

// StrainLimitKey::axis of a non-inversion floor row (StrainLimitSettings::inversion_floor):
// C = (s_i - s_floor) / (1 - s_floor) on every principal stretch, bound kMin, any frame.
inline constexpr std::int8_t kStrainFloorAxis = 3;

// Identity of a strain-limit row for warm starts, stable when singular values swap order
// (docs/math.md §2 R3): it never uses the principal index i. Instead principal direction v_i is
// named by the material axis it is matched to, m = pi(i), where pi is the permutation maximising
// sum_i |V'_{pi(i) i}| (each principal direction to its nearest limit axis, one to one).
struct StrainLimitKey {
  int element = -1;
  // limit axis j (hyperbolic, OP); = principal_axis (LI, ellipsoid); kStrainFloorAxis (floor)
  std::int8_t axis = -1;
  std::int8_t principal_axis = -1;  // m = pi(i), the matched material axis of v_i
  StrainBound bound = StrainBound::kMax;

  // Equal element, axis, principal_axis and bound.
  bool operator==(const StrainLimitKey& other) const;
  // The fields in the order of the row key's layout (kStrainLimitRowKey,
  // constraints/row_key_layouts.h): element, axis, principal_axis, bound.
  std::array<std::int64_t, 4> Fields() const;
  // One integer for hash maps: the fields packed as a row key's payload (no source id).
  std::uint64_t Pack() const;
  // Inverse of Pack (bits above the payload, e.g. a source id, must be cleared).
  static StrainLimitKey Unpack(std::uint64_t packed);
};

// One constraint row C(x) >= 0 of a tet, linearised: C(x + dx) ~ C + J . dx.
struct StrainLimitRow {
  Vec12 J = Vec12::Zero();  // dC/dx, ordered (x_1, x_2, x_3, x_4) each xyz [1/m]
  double C = 0.0;           // >= 0 feasible; 1 at rest, 0 at the limit [-]
  StrainLimitKey key;
  std::int8_t principal_index = -1;  // i in the sorted signed SVD: diagnostics only, not identity
};

// Appends to `rows` the rows of element `element` with C < tau (params.activation_margin), with
// exact Jacobians (gap clamp R1; dV/dx = 0 when params.freeze_frame_jacobian). Q is the element's
// limit frame (SelectStrainLimitFrame). Returns the number of rows appended. No allocation beyond
// the growth of `rows`.
int AppendStrainLimitRows(int element, const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                          const StrainLimitParams& params, std::vector<StrainLimitRow>* rows);

// As above, with the signed SVD of G = sum_n x_n r_n^T already computed.
int AppendStrainLimitRows(int element, const TetRestRows& r, const SignedSvd& svd, const Mat3& Q,
                          const StrainLimitParams& params, std::vector<StrainLimitRow>* rows);

// Largest violation max(0, -C) over all rows of the element (no margin, no Jacobian).
double CalcStrainLimitViolation(const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                                const StrainLimitParams& params);

// Strain along the material direction q (unit, rest coordinates): |G q| - 1.
double CalcMaterialAxisStrain(const TetRestRows& r, const TetPositions& x, const Vec3& q);

// The permutation pi used by StrainLimitKey: result[i] = material axis matched to column i of
// V' = Q^T V, maximising sum_i |V'_{pi(i) i}| (the first maximum of the six on ties).
std::array<int, 3> CalcPrincipalAxisMatch(const Mat3& V_prime);

// The principal index i whose direction is matched to material axis m (match[i] == m).
int FindMatchedPrincipalIndex(const std::array<int, 3>& match, int m);

}  // namespace taut
