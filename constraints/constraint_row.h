// One linearized constraint row of an island and the interface of everything that emits rows.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "plugin/deformable_body.h"

namespace taut {

// Largest number of nodes one row touches (a hex, or an embedded point with trilinear weights).
constexpr int kMaxRowNodes = 8;

// What a row constrains, for statistics.
enum class RowType : std::uint8_t { kStrainLimit, kEnergyLimit, kContact };

// C(x) >= 0 linearized at the current iterate: C + J dx >= 0, with J sparse over the nodes of one
// deformable body (MATH.md §5). C is dimensionless for limit rows, J in 1/m.
struct ConstraintRow {
  std::uint64_t key = 0;  // identity for warm starting (source id and element, axis, bound)
  double C = 0.0;         // value at the iterate, >= 0 feasible
  int body = -1;          // index of the deformable body in the island
  int num_nodes = 0;
  RowType type = RowType::kStrainLimit;
  // Friction rows (contact tangents): 1 or 2 = how many rows back the contact's normal row is;
  // 0 for unilateral rows. A friction row targets J v = 0 within the Coulomb disk of radius
  // mu lambda_n; its C is unused.
  int friction_of = 0;
  double mu = 0.0;  // Coulomb coefficient of a friction row
  std::array<int, kMaxRowNodes> nodes{};  // node indices in the body
  std::array<Vec3, kMaxRowNodes> J{};     // dC/dx_node
};

// A family of unilateral constraints on one deformable body (strain limits, energy limits).
class ConstraintSource {
 public:
  virtual ~ConstraintSource() = default;
  // The body the rows act on.
  virtual const DeformableBody& body() const = 0;
  // Appends the rows that are violated or within the activation margin at positions x (3N),
  // tagging them with `body_index`. Returns how many were appended.
  virtual int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) = 0;
  // Largest violation max(0, -C) over every constraint of the family at x (nonlinear).
  virtual double CalcMaxViolation(const VecX& x) const = 0;
  // Sum of violations max(0, -C) over every constraint at x (the merit function's penalty).
  virtual double CalcViolationSum(const VecX& x) const = 0;
};

}  // namespace taut
