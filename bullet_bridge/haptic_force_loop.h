// A haptic loop (docs/haptics.md): the force a driven tool feels, re-solved at ~1 kHz from the
// last world step's contact and limit LCP while the full step runs slower.
#pragma once

#include <BulletDynamics/Dynamics/btRigidBody.h>

#include "bullet_bridge/deformable_world.h"
#include "constraints/frozen_island_lcp.h"

namespace taut {

// The tool's motion since the step the loop was captured from: its displacement [m] and its
// rotation vector [rad] (axis times angle), world frame, about the tool's reference point.
struct ToolMotion {
  Vec3 displacement = Vec3::Zero();
  Vec3 rotation = Vec3::Zero();
};

// What one haptic query found.
struct HapticWrench {
  Vec3 force = Vec3::Zero();   // on the tool from the frozen rows, J_t^T lambda / h [N]
  Vec3 torque = Vec3::Zero();  // about the tool's reference point [N m]
  int sweeps = 0;              // PGS sweeps of this query
  double residual = 0.0;       // natural-map LCP residual at exit (lcp_residual.h)
  bool converged = false;      // a PGS tolerance was met
  double microseconds = 0.0;   // wall time of the query
};

// The contact and limit LCP of the islands a rigid body (the tool: a probe, an instrument, or the
// bone that drives a finger's flesh) acts on, frozen at the end of a world step, as a function of
// the tool's motion since then (SOFA's LCPForceFeedback; docs/haptics.md):
//   u = (displacement / h; rotation / h),  w = W lambda + q0 + J_t u,  wrench = J_t^T lambda / h
// (constraints/frozen_island_lcp.h eq. H1-H2). A static or kinematic tool acts through contact
// rows whose partner it is (eq. H4) and through the kinematic nodes AttachNodesToRigidBody pinned
// to it (eq. H5); a dynamic tool through its own rows in its island (contacts, attachments,
// Bullet's manifolds and joints; eq. H6), its velocity taken from the user: it leaves W.
// W, q0, J_t and the warm start are copies: queries read nothing of the world, so they may run
// on another thread while the world steps on, and leave the simulation bit-identical. With no
// motion the wrench is the step's own on the tool (to the PGS tolerance); a query answers for
// the step redone with the tool moved, linearized at the step (same rows, A, rotations).
class HapticForceLoop {
 public:
  HapticForceLoop() = default;
  // Freezes the islands of the world's last substep that `tool` acts on. The tool's reference
  // point is its centre of mass (the wrench's torque is about it, as in RigidBodyWrench). Call it
  // right after stepSimulation: it reads the substep's A^-1 (solves with each body's held
  // factor), v*, v, rows and the models' element rotations, and changes none of them. Throws
  // InputError for a tool that is not in the world, and for an island whose body holds no factor
  // of this step's A (FreezeIsland). A tool that touches nothing gives a loop of 0 rows and a
  // zero wrench.
  static HapticForceLoop Capture(DeformableWorld& world, const btRigidBody* tool);

  // The wrench on the tool after `motion` since the step, warm-started from the last query.
  HapticWrench CalcToolWrench(const ToolMotion& motion);
  // The same for the tool's world transform now (the motion from its transform at Capture).
  HapticWrench CalcToolWrench(const btTransform& tool_now);

  // PGS controls of the queries (Capture copies the world's SqpSettings::pgs, the step's own).
  PgsSettings& mutable_pgs_settings() { return pgs_; }
  // The substep h [s] and the tool's transform at Capture.
  double h() const { return h_; }
  const btTransform& tool_transform() const { return tool_transform_; }
  const Vec3& reference_point() const { return reference_; }
  // The frozen problem (rows, W, J_t, the last query's multipliers).
  const FrozenIslandLcp& lcp() const { return lcp_; }
  // Islands frozen and rows the tool moves (nonzero J_t row).
  int num_islands() const { return num_islands_; }
  int num_tool_rows() const { return num_tool_rows_; }

 private:
  FrozenIslandLcp lcp_;
  PgsSettings pgs_;
  double h_ = 0.0;
  btTransform tool_transform_ = btTransform::getIdentity();
  Vec3 reference_ = Vec3::Zero();
  int num_islands_ = 0;
  int num_tool_rows_ = 0;
};

}  // namespace taut
