// One linearized constraint row of an island and the interface of everything that emits rows.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "constraints/island_body.h"
#include "constraints/row_key.h"
#include "constraints/row_types.h"
#include "plugin/deformable_body.h"

namespace taut {

// Largest number of nodes one row touches (a hex, or an embedded point with trilinear weights).
constexpr int kMaxRowNodes = 8;

// C(x) >= 0 linearized at the current iterate: C + J dx >= 0 (docs/math.md §5.3), or C = 0 for a
// bilateral row. J is sparse over at most two island bodies ("sides"): the nodes of side A
// (body, nodes, J) and optionally of side B (body2, nodes2, J2). A rigid island body has two
// velocity blocks, linear (block 0) and angular (block 1). C is dimensionless for limit rows, J
// in 1/m; contact rows have C in m and dimensionless J.
struct ConstraintRow {
  std::uint64_t key = 0;  // identity for warm starting (constraints/row_key_layouts.h)
  double C = 0.0;         // value at the iterate, >= 0 feasible (bilateral: = 0 feasible)
  int body = -1;          // index of side A's body in the island
  int num_nodes = 0;
  // Element of `body` whose nodes are `nodes` (strain and energy rows; -1 for other rows): its
  // node blocks lie in the body's Newton pattern, addressed through the element's value map.
  int element = -1;
  RowType type = RowType::kStrainLimit;
  bool bilateral = false;  // C = 0 with lo <= lambda <= hi (joints, attachments)
  double lo = -std::numeric_limits<double>::infinity();  // bilateral rows: multiplier bounds
  double hi = std::numeric_limits<double>::infinity();   // (finite: motors, friction joints)
  // Friction rows (contact tangents): 1 or 2 = how many rows back the contact's normal row is;
  // 0 for unilateral rows. A friction row targets J v = 0 within the Coulomb disk of radius
  // mu lambda_n; its C is unused.
  int friction_of = 0;
  double mu = 0.0;  // Coulomb coefficient of a friction row
  // The row's curvature term (CollectCurvature) is its full second derivative, frame factor
  // included (strain rows of docs/math.md §5.9): the primal path's inner solves converge on it,
  // so a stalled complementarity residual is the multiplier iteration's (penalty growth, §5.8).
  bool full_curvature = false;
  // The row's curvature term is its whole second derivative (full_curvature rows, and ellipsoid
  // rows of equal axis limits, whose C depends on one stretch only): the primal path's model of
  // Phi is trusted for model steps (docs/math.md §5.8, model steps).
  bool exact_curvature = false;
  // J^T (-d^2C/dx^2) J of a limit row whose source knows it (energy rows), else 0: with the
  // row's multiplier, the stiffness its own curvature adds along J, which the primal path's
  // penalty counts in the row's effective mass (docs/math.md §5.8, penalties).
  double curvature_along_j = 0.0;
  std::array<int, kMaxRowNodes> nodes{};  // node indices in the body
  std::array<Vec3, kMaxRowNodes> J{};     // dC/dx_node
  int body2 = -1;                         // side B's body in the island, -1 when one-sided
  int num_nodes2 = 0;
  std::array<int, kMaxRowNodes> nodes2{};
  std::array<Vec3, kMaxRowNodes> J2{};

  // Calls f(body, block, J) for every velocity block the row touches, both sides.
  template <typename F>
  void ForEachEntry(F&& f) const {
    for (int n = 0; n < num_nodes; ++n) f(body, nodes[n], J[n]);
    for (int n = 0; n < num_nodes2; ++n) f(body2, nodes2[n], J2[n]);
  }
  // Violation of the row at its C: max(0, -C); bilateral |C| (0 when a bound is finite: such a
  // row may rightly stay unsatisfied at its bound); friction rows 0.
  double violation() const {
    if (friction_of > 0) return 0.0;
    if (!bilateral) return std::max(0.0, -C);
    return std::isinf(lo) && std::isinf(hi) ? std::abs(C) : 0.0;
  }
};

// Rows a contact emits: its normal row, then two friction rows only when mu > 0. A frictionless
// contact's tangent multipliers are held at 0 by the Coulomb disk |lambda_t| <= 0, so its
// tangent rows carry no force: they would only add rows to the QP and make it a mixed
// complementarity problem (no active-set polish on the dual path; docs/math.md §5.5).
inline int CountContactRows(double mu) { return mu > 0.0 ? 3 : 1; }

// Two unit tangents t1, t2 completing the unit normal n to a right-handed frame (n, t1, t2 = n x
// t1): the friction directions of a contact (docs/math.md §5.5).
inline void CalcContactTangents(const Vec3& n, Vec3& t1, Vec3& t2) {
  t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  t2 = n.cross(t1);
}

// Receives curvature blocks of rows for the SQP metric / Newton matrix (docs/math.md §5.9):
// blocks of weight * [-d^2 C / dx^2]_+ between two nodes of one deformable body.
class CurvatureSink {
 public:
  virtual ~CurvatureSink() = default;
  // metric(body; node_a, node_b) += block (3x3, dC^2/dx_a dx_b units times the weight).
  virtual void AddBlock(int body, int node_a, int node_b, const Mat3& block) = 0;
  // metric(body; nodes of `element`) += block (3k x 3k over the element's k nodes, node-major).
  // By default one AddBlock per node pair.
  virtual void AddElementBlock(int body, int element, const int* nodes,
                               const Eigen::Ref<const MatX>& block) {
    (void)element;
    const int k = static_cast<int>(block.rows() / 3);
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        AddBlock(body, nodes[a], nodes[b], block.block<3, 3>(3 * a, 3 * b));
  }
};

// Anything that emits rows for an island (limits, contacts, joints), evaluated at an iterate.
class ConstraintSource {
 public:
  virtual ~ConstraintSource() = default;
  // Adds weights[c] * [-d^2 C_c/dx^2]_+ (negative curvature modes clamped to 0, so the sum stays
  // positive semi-definite) for each of the `count` rows that this source emitted (matched by the
  // key's source id), at the iterate. weights[c] >= 0 (h * lambda_c); rows of other sources and
  // rows with weight 0 are skipped. Default: rows without curvature (contacts, joints: linear J).
  virtual void AddIslandCurvature(const IslandIterate& /*iterate*/, const ConstraintRow* /*rows*/,
                                  const double* /*weights*/, int /*count*/,
                                  CurvatureSink& /*sink*/) const {}
  // Appends the rows active at the iterate (violated or within the activation margin). Returns
  // how many were appended.
  virtual int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) = 0;
  // Sum of violations over every constraint (the merit function's penalty).
  virtual double CalcIslandViolationSum(const IslandIterate& iterate) const = 0;
};

// A family of unilateral constraints on one deformable body (strain limits, energy limits,
// contacts with immovable objects), evaluated at that body's positions.
class BodyConstraintSource : public ConstraintSource {
 public:
  // The body the rows act on.
  virtual const DeformableBody& body() const = 0;
  // Appends the rows that are violated or within the activation margin at positions x (3N),
  // tagging them with `body_index`. Returns how many were appended.
  virtual int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) = 0;
  // Largest violation max(0, -C) over every constraint of the family at x (nonlinear).
  virtual double CalcMaxViolation(const VecX& x) const = 0;
  // Sum of violations max(0, -C) over every constraint at x (the merit function's penalty).
  virtual double CalcViolationSum(const VecX& x) const = 0;

  // The island interface, through the body's positions at the iterate.
  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override {
    const int b = iterate.IndexOf(&body());
    return AppendRows(iterate.x(b), b, rows);
  }
  double CalcIslandViolationSum(const IslandIterate& iterate) const override {
    return CalcViolationSum(iterate.x(iterate.IndexOf(&body())));
  }
};

}  // namespace taut
