// Settings a deformable body is made from (validated when the body is made).
#pragma once

#include <string>

#include "plugin/material.h"

namespace taut {

// Factor reuse in a body's unconstrained solve (ImplicitSystem::SolveStep, docs/solver.md): a
// body whose factorization of A costs at least min_refactor_cost PCG iterations solves the next
// steps by CG preconditioned with the last factor, to a relative residual of pcg_tolerance, and
// refactors when CG needs more than half that cost or the constraint solve needs A^-1.
struct FactorReuseSettings {
  bool enabled = true;
  double min_refactor_cost = 8.0;  // > 0
  // in (0, 1). 1e-6 (was 1e-10): the reusing cantilever of tests/factor_reuse_test.cc then stays
  // within 2e-7 of its sag of the body that factors every step, over 40 steps (docs/solver.md).
  double pcg_tolerance = 1e-6;
};

// Material, damping and identity of one deformable body.
struct DeformableBodySettings {
  std::string name = "body";       // used in error messages and reports
  Material material;               // E, nu, rho (validated: E > 0, nu in (-1, 0.5), rho > 0)
  double mass_damping = 0.0;       // Rayleigh alpha [1/s], >= 0: damping force -alpha M v
  double stiffness_damping = 0.0;  // Rayleigh beta [s], >= 0: damping force -beta K v
  double friction = 0.5;           // Coulomb coefficient >= 0, times the rigid object's friction
  double contact_margin = 0.01;    // [m] > 0: nodes closer than this to a rigid shape get rows
  // Newton restitution e in [0, 1] of contacts with rigid objects, times the object's
  // getRestitution() (Bullet's product rule): a contact closing faster than Bullet's
  // m_restitutionVelocityThreshold [m/s] separates at >= e times its approach speed. Default 0
  // (no bounce). Contacts between deformables and self-contacts have none.
  double restitution = 0.0;
  // Contacts of the body's boundary nodes with its own boundary triangles (docs/math.md §5.5,
  // self-contact), off by default.
  bool self_collision = false;
  // Contacts of convex rigid shapes with the body's boundary triangles, besides its contact
  // points: a shape's deepest point below a triangle gets rows on the triangle's 3 nodes (face
  // contact, docs/math.md §5.5), so a sphere or a capsule edge cannot sink between the nodes.
  // Off by default; surfaces whose corners are not single nodes (embedded) use points only.
  bool face_contact = false;
  // [m/s] > 0 (+inf disables): a free node faster than this after the unconstrained solve or at
  // the end of a step counts as an explosion; the step throws SimulationError. Default 1e3 m/s.
  double max_speed = 1e3;
  FactorReuseSettings factor_reuse;  // of the unconstrained solve (validated)
  // Throws InputError naming the body and the quantity when out of range.
  void Validate() const;
};

}  // namespace taut
