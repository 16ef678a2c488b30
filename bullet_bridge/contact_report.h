// Forces out (docs/architecture.md §3, stage 8): what the island solves of one substep applied,
// read from the solved multipliers of the rows (impulses over the substep h). Per deformable body
// its contact points (normal and friction impulse, force = impulse / h), per rigid object the
// total wrench it received from deformables, and per element the multiplier of each collected
// strain- or energy-limit row. Reading them changes nothing in the simulation.
//
// Sign convention: a contact's impulses and force act ON the deformable body the point belongs
// to; its partner receives the equal and opposite impulse (the rows' J_B = -J_A). A wrench is
// what the rigid object received: its force is minus the sum of the contact forces of that object
// on the deformables (plus, for a dynamic body, the reactions of its attached nodes).
//
// The figures are the solver's answer, as accurate as its tolerances: the dual path keeps every
// friction impulse on the disk of its normal impulse; the primal path projects onto the disk of
// the previous multiplier iterate's and, stopped at its iteration cap, can leave friction ~1 %
// outside the cone (tests/contact_force_test.cc).
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <cstdint>
#include <vector>

#include "constraints/island_body.h"
#include "constraints/island_rows.h"
#include "plugin/deformable_body.h"

namespace taut {

// One contact of a deformable body in the last substep, as its island's solve left it: a contact
// row with a nonzero impulse or a gap <= 0 (points merely within the contact margin are left
// out). Vectors in world coordinates, positions and gap at the end of the substep (x = x0 + h v).
struct DeformableContactPoint {
  const DeformableBody* body = nullptr;  // the body the impulses act on
  // Index of the contact point in the body's contact surface (a boundary node, or a vertex of
  // the surface given to SetContactSurface); -1 when the contact is another deformable's point on
  // a surface triangle of this body, or a rigid shape's face contact (then `triangle` says which).
  int point = -1;
  // Boundary triangle of this body touched by a partner's point or by a rigid shape's deepest
  // point (DeformableBodySettings::face_contact), else -1.
  int triangle = -1;
  int node = -1;  // the node when the contact point is a single node, else -1
  // The partner: a rigid object (static, kinematic or dynamic), or another deformable body.
  const btCollisionObject* partner_object = nullptr;
  const DeformableBody* partner_body = nullptr;
  Vec3 position = Vec3::Zero();  // the contact point on this body [m]
  // Unit normal from the partner towards this body: the direction the partner pushes [-].
  Vec3 normal = Vec3::Zero();
  double gap = 0.0;  // signed distance to the partner along `normal` [m], < 0 penetrating
  double normal_impulse = 0.0;  // lambda_n >= 0 over the substep [N s]
  // Tangential impulse lambda_t1 t1 + lambda_t2 t2 [N s]; Coulomb: |.| <= mu lambda_n.
  Vec3 friction_impulse = Vec3::Zero();
  double mu = 0.0;  // friction coefficient of the contact (product of the two) [-]
  // Mean force over the substep, (lambda_n normal + friction_impulse) / h [N].
  Vec3 force = Vec3::Zero();
};

// The total wrench one rigid object received from every deformable in the last substep
// (contacts and, for dynamic bodies, node attachments), world frame.
struct RigidBodyWrench {
  const btCollisionObject* object = nullptr;
  const btRigidBody* rigid = nullptr;  // btRigidBody::upcast(object), null when not a rigid body
  Vec3 force = Vec3::Zero();           // sum of the impulses it received divided by h [N]
  // About its centre of mass at the end of the substep (the solve's predicted transform for a
  // dynamic body, the world transform's origin for a static or kinematic one) [N m].
  Vec3 torque = Vec3::Zero();
  int num_contacts = 0;  // deformable contact points with an impulse or a gap <= 0
};

// What a limit row bounds.
enum class LimitRowKind : std::uint8_t {
  kStrainMin,    // a principal stretch's lower limit (StrainLimitSource)
  kStrainMax,    // a principal stretch's upper limit
  kEnergy,       // the element's elastic energy U_e <= U_max (EnergyLimitSource)
  kStrainFloor,  // a principal stretch's non-inversion floor (StrainLimitSettings::inversion_floor)
};

// One strain- or energy-limit row the solve held (every row collected at its final velocities:
// violated or within the activation margin) with its multiplier. lambda > 0 only on rows at the
// limit (C ~ 0, complementarity within the solver's tolerance).
struct LimitRowMultiplier {
  const DeformableBody* body = nullptr;
  int element = -1;
  LimitRowKind kind = LimitRowKind::kStrainMax;
  int axis = -1;  // strain rows: limit axis j (0-2), else -1 (kStrainLimitRowKey; floor rows: 3)
  int principal_axis = -1;  // strain rows: matched material axis m = pi(i) (0-2), else -1
  double C = 0.0;           // row value at the end of the substep: 0 at the limit, < 0 violated [-]
  // lambda >= 0: J [1/m] maps it to nodal impulses J_n lambda [N s], so its unit is N m s.
  double multiplier = 0.0;
  double max_nodal_force = 0.0;  // max over the row's nodes of |J_n| lambda / h: how hard [N]
};

// Everything one substep's island solves applied. Filled by DeformableWorld after each substep;
// only the last substep's is kept.
struct SubstepForces {
  double h = 0.0;  // the substep [s]; 0 before the first substep with deformables
  std::vector<DeformableContactPoint> contacts;  // grouped by island, then in row order
  std::vector<RigidBodyWrench> wrenches;         // one per rigid object that received any
  std::vector<LimitRowMultiplier> limits;

  // Empties the lists (keeping their storage) for a substep of length h.
  void Clear(double h);
};

// Appends one solved island's contacts, wrenches and limit multipliers to `forces`: `rows` and
// `lambda` (one multiplier per row) as IslandSolver::last_rows() / last_multipliers() left them,
// `bodies` the island's bodies in the rows' indexing, `objects` the world's collision objects
// (rigid contact keys name the partner by its world index).
void AppendIslandForces(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const btCollisionObjectArray& objects,
                        SubstepForces& forces);

}  // namespace taut
