// The element under a point of a contact-surface triangle, for ray queries on deformable bodies.
#pragma once

#include "plugin/contact_surface.h"
#include "plugin/element_model.h"

namespace taut {

// The element a point `hit` [m] of triangle `triangle` of `surface` lies in, at node positions x
// (3N). Candidates are the elements that hold every node of at least one of the triangle's
// corner points (for a boundary triangle of nodes: the elements at its corners; for an embedded
// surface: each corner vertex's own element). Among them, in this order of preference: a tet
// whose barycentric coordinates of `hit` are all >= -1e-9 (it contains the point); the element
// holding the most corners (the boundary face's own element holds all three); the element whose
// node centroid is nearest. Returns -1 only when no element holds a corner point's nodes.
int FindHitElement(const ElementModel& model, const VecX& x, const ContactSurface& surface,
                   int triangle, const Vec3& hit);

namespace internal {

// Barycentric coordinates of p in the tet (a, b, c, d): p = l0 a + l1 b + l2 c + l3 d, sum 1.
// All four are NaN for a degenerate tet.
Eigen::Vector4d CalcTetBarycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                   const Vec3& d);

}  // namespace internal
}  // namespace taut
