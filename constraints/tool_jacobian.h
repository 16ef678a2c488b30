// The tool Jacobian J_t = dw/du of the haptic loop (docs/haptics.md eq. H4, H5): how a tool's
// twist u moves the row velocities w of a frozen island, for a tool the rows touch (a rigid
// partner of contact rows) and for a tool that drives nodes of a deformable body (a bone).
#pragma once

#include <vector>

#include "constraints/frozen_island_lcp.h"
#include "constraints/island_rows.h"
#include "plugin/deformable_body.h"

namespace taut {

// J_t row of a row whose partner is a rigid tool at the tool's point q (world), the row's
// direction d on the body (J_A = w_n d, weights summing to 1) and the tool's reference point o:
//   w = J_A v - d . (u_lin + u_ang x (q - o))  =>  J_t,c = -[d; (q - o) x d].        (H4)
Eigen::Matrix<double, 1, 6> CalcRigidPointToolRow(const Vec3& d, const Vec3& q, const Vec3& o);

// Adds to J_t the entries of the rows on island body `b`, a rigid tool whose twist (linear and
// angular velocity, blocks 0 and 1, angular about its centre of mass) is prescribed:
//   w = J_other v_other + J_b u  =>  J_t,c += [J_c,block0; J_c,block1].               (H6)
void AddPrescribedBodyToolJacobian(const IslandRows& rows, int b, ToolJacobian& J_t);

// Adds to J_t (rows.size() x 6) the part of the kinematic nodes `nodes` of island body `b`
// (`body`) that move with the tool: node n's velocity is G_n u = u_lin + u_ang x (x_n - o), and
// the free nodes' v* = A^-1 (b - c_K K_fk v_kin) follows them (DeformableBody::BeginStep), so
//   J_t = J_k G - c_K Y^T K G,   Y = A^-1 J^T,  c_K = h beta + h^2.                  (H5)
// K is the body model's stiffness at its last rotation update (the step's x0, unless the model
// was updated since); Y_b are body b's columns (FrozenIsland::Y). Throws InputError for a node
// index out of range or one that is not kinematic.
void AddDrivenNodesToolJacobian(const IslandRows& rows, int b, const DeformableBody& body,
                                const std::vector<int>& nodes, const Vec3& o, double c_K,
                                const MatX& Y_b, ToolJacobian& J_t);

}  // namespace taut
