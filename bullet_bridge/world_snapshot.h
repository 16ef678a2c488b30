// A snapshot of a DeformableWorld's state (DeformableWorld::SaveSnapshot, RestoreSnapshot), e.g.
// for the resets of reinforcement learning or the restarts of an optimization: a restored world
// continues bit-identically to the world it was saved from.
#pragma once

#include <array>
#include <vector>

#include "bullet_bridge/bullet_world_state.h"
#include "bullet_bridge/contact_report.h"
#include "constraints/island_solver.h"
#include "constraints/step_stats.h"
#include "plugin/deformable_body.h"

namespace taut {

// Everything the next step of a DeformableWorld depends on besides its configuration (bodies,
// meshes, settings, limits, attachments, Bullet's objects, shapes and joints), as a copyable
// value: taken once, it can be restored any number of times, into the world it was taken from or
// into one built the same way. Bodies and objects are referred to by their index in the world.
// The fields are for inspection; only SaveSnapshot makes a consistent one.
struct WorldSnapshot {
  // One deformable body (world order) and the solver of the islands it leads.
  struct Deformable {
    int num_elements = 0;        // checked on restore, with the body's node count
    DeformableBody::State body;  // x, v, queued forces, node kinds, Newton factor
    IslandSolver::State solver;  // warm starts by row key, the path rule's memory
  };
  // The contact source of two deformables, kept across steps: its id is in its rows' keys.
  struct PairContact {
    int first = -1, second = -1;  // deformable indices, first < second
    int source_id = -1;
  };
  // The last substep's forces out with their pointers as world indices (-1: none).
  struct Forces {
    SubstepForces values;  // its pointers are null; the indices below stand for them
    std::vector<std::array<int, 3>> contacts;  // per contact: body, partner body, partner object
    std::vector<int> wrenches;                 // per wrench: collision object
    std::vector<int> limits;                   // per limit row: body
  };

  std::vector<Deformable> deformables;
  std::vector<PairContact> pair_contacts;
  std::vector<std::array<int, 2>> island_source_ids;  // manifold, joint source per island slot
  int next_source_id = 0;                             // the world's next row-key source id
  BulletWorldState bullet;         // rigid bodies, joints, contact manifolds, solver seed
  btScalar local_time = 0.0;       // time stepSimulation has accumulated but not simulated [s]
  btScalar fixed_time_step = 0.0;  // the last stepSimulation's substep [s]
  StepStats last_step_stats;
  StepStats last_call_stats;
  Forces forces;
};

}  // namespace taut
