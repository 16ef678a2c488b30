// Face contact of rigid shapes with a deformable's boundary triangles
// (DeformableBodySettings::face_contact, docs/math.md §5.5): a ball smaller than the block's
// surface cells, dropped between its nodes, falls through a body that touches rigid shapes at
// its nodes only, and rests on its surface with face contact, carried by the face rows; a thin
// capsule rolled over a soft slab stays on its surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/surface_mesh.h"

namespace taut {
namespace {

constexpr double kStep = 1.0 / 240.0;
constexpr double kRadius = 0.05;  // [m], less than the 0.14 m from a cell centre to its nodes
constexpr double kTop = 0.1;      // [m] the block's top face
constexpr double kMass = 1.0;     // [kg]

struct BallOnBlock {
  BulletWorldHolder holder;
  DeformableBody* block = nullptr;
  btRigidBody* ball = nullptr;
};

// A 1 kg ball released 2 cm above the centre of a top cell of a stiff 0.4 x 0.4 x 0.1 m block
// (E = 10 MPa, 2 x 2 x 1 cells of 0.2 m, bottom clamped), stepped for `steps` steps.
void DropBetweenNodes(bool face_contact, int steps, BallOnBlock& scene) {
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {1e7, 0.3, 1000.0};
  settings.face_contact = face_contact;
  scene.block = scene.holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.4, 0.4, kTop), 2, 2, 1, Vec3(-0.2, -0.2, 0.0)), settings);
  scene.block->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
  scene.ball = scene.holder.AddRigidBody(std::make_unique<btSphereShape>(kRadius), kMass,
                                         btVector3(0.1, 0.1, kTop + kRadius + 0.02), 0.5, 0.0);
  for (int i = 0; i < steps; ++i) scene.holder.world.stepSimulation(kStep, 1, kStep);
}

double BallBottom(const BallOnBlock& scene) {
  return static_cast<double>(scene.ball->getCenterOfMassPosition().z()) - kRadius;
}

TEST(FaceContactTest, IsOffByDefault) { EXPECT_FALSE(DeformableBodySettings().face_contact); }

TEST(FaceContactTest, BallBetweenTheNodesFallsThroughWithoutFaceContact) {
  BallOnBlock scene;
  DropBetweenNodes(false, 120, scene);
  std::printf("without face contact: ball bottom %.4f m after 0.5 s (top face %.2f m)\n",
              BallBottom(scene), kTop);
  EXPECT_LT(BallBottom(scene), 0.0) << "no node is within reach of the ball";
}

TEST(FaceContactTest, BallBetweenTheNodesRestsOnTheFaceAndItsWeightIsReported) {
  BallOnBlock scene;
  DropBetweenNodes(true, 240, scene);
  const double bottom = BallBottom(scene);
  const double vz = static_cast<double>(scene.ball->getLinearVelocity().z());
  // The face rows carry the weight: the normal forces of the contacts on triangles, summed.
  const SubstepForces& forces = scene.holder.world.last_substep_forces();
  double face_force = 0.0, node_force = 0.0;
  for (const DeformableContactPoint& contact : forces.contacts)
    (contact.triangle >= 0 ? face_force : node_force) += contact.force.z();
  const double weight = kMass * 9.81;
  std::printf(
      "with face contact: ball bottom %.5f m (top face %.2f m), v_z %.2e m/s, face force "
      "%.4f N, node force %.4f N, weight %.4f N\n",
      bottom, kTop, vz, face_force, node_force, weight);
  // On the surface: the stiff block gives way by well under a millimetre under 9.8 N, and the
  // contact tolerance is 1e-5 m.
  EXPECT_GT(bottom, kTop - 1e-3);
  EXPECT_LT(bottom, kTop + 1e-4);
  EXPECT_LT(std::abs(vz), 1e-2);
  EXPECT_EQ(node_force, 0.0) << "no node is within reach of the ball";
  // The ball pushes the block down (force on the block along -z) by its weight.
  EXPECT_NEAR(-face_force / weight, 1.0, 0.005);
}

TEST(FaceContactTest, BallRestsOnTheTrianglesOfAnEmbeddedContactSurface) {
  // A one-cell tet block (0.4 x 0.4 x 0.1 m, 8 nodes) whose contact surface is its own box
  // surface inset by 1 mm, two triangles per face: the embedded corners are 0.28 m from the
  // ball's centre, so only the triangles (4-node corner points, merged onto the 8 nodes) hold it.
  for (bool face_contact : {false, true}) {
    BulletWorldHolder holder;
    DeformableBodySettings settings;
    settings.name = "block";
    settings.material = {1e7, 0.3, 1000.0};
    settings.face_contact = face_contact;
    DeformableBody* block = holder.world.AddTetBody(
        MakeBoxTetMesh(Vec3(0.4, 0.4, kTop), 1, 1, 1, Vec3(-0.2, -0.2, 0.0)), settings);
    block->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
    constexpr double kInset = 1e-3;
    holder.world.SetContactSurface(
        block, MakeBoxSurface(Vec3(0.4 - 2 * kInset, 0.4 - 2 * kInset, kTop - 2 * kInset), 1, 1, 1,
                              Vec3(-0.2 + kInset, -0.2 + kInset, kInset)));
    btRigidBody* ball = holder.AddRigidBody(std::make_unique<btSphereShape>(kRadius), kMass,
                                            btVector3(0.03, -0.04, kTop + kRadius), 0.5, 0.0);
    for (int i = 0; i < 240; ++i) holder.world.stepSimulation(kStep, 1, kStep);
    const double bottom = static_cast<double>(ball->getCenterOfMassPosition().z()) - kRadius;
    double face_force = 0.0;
    for (const DeformableContactPoint& contact : holder.world.last_contacts(block))
      if (contact.triangle >= 0) face_force += contact.force.z();
    std::printf(
        "embedded surface, face contact %s: ball bottom %.5f m (surface %.3f m), face "
        "force %.4f N\n",
        face_contact ? "on" : "off", bottom, kTop - kInset, face_force);
    if (!face_contact) {
      EXPECT_LT(bottom, 0.0) << "the embedded vertices are out of the ball's reach";
      continue;
    }
    EXPECT_NEAR(bottom, kTop - kInset, 1e-4);
    EXPECT_NEAR(-face_force / (kMass * 9.81), 1.0, 0.005);
  }
}

struct CapsuleRoll {
  double deepest_gap = 0.0;    // [m] most negative contact gap of the capsule after landing
  double highest_gap = -1.0;   // [m] largest per-step smallest gap (how far it floated)
  double lowest_bottom = 1e9;  // [m] lowest point of the capsule over the run
  double travel = 0.0;         // [m] distance rolled along x
  int steps_without_contact = 0;
};

// A 0.25 kg capsule of radius 2 cm (below the 0.1 m node spacing) lying across a soft slab
// (E = 200 kPa, 0.6 x 0.3 x 0.05 m, 6 x 3 x 1 cells, bottom clamped) between two rows of nodes,
// rolled along x at 0.2 m/s for 1 s: its contact gaps each step once it has landed (0.1 s).
CapsuleRoll RollCapsule(bool face_contact) {
  BulletWorldHolder holder;
  DeformableBodySettings settings;
  settings.name = "slab";
  settings.material = {2e5, 0.3, 1000.0};
  settings.friction = 1.0;
  settings.face_contact = face_contact;
  DeformableBody* slab = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.6, 0.3, 0.05), 6, 3, 1, Vec3(0.0, 0.0, 0.0)), settings);
  slab->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
  constexpr double kCapsuleRadius = 0.02;
  btRigidBody* capsule =
      holder.AddRigidBody(std::make_unique<btCapsuleShape>(kCapsuleRadius, 0.16), 0.25,
                          btVector3(0.15, 0.15, 0.05 + kCapsuleRadius), 1.0, 0.0);
  capsule->setActivationState(DISABLE_DEACTIVATION);
  capsule->setLinearVelocity(btVector3(0.2, 0, 0));
  capsule->setAngularVelocity(btVector3(0, 0.2 / kCapsuleRadius, 0));  // rolling: v = w r
  const double x0 = static_cast<double>(capsule->getCenterOfMassPosition().x());
  CapsuleRoll roll;
  for (int i = 0; i < 240; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    const double bottom =
        static_cast<double>(capsule->getCenterOfMassPosition().z()) - kCapsuleRadius;
    roll.lowest_bottom = std::min(roll.lowest_bottom, bottom);
    if (i < 24) continue;
    double smallest = 1e9;
    for (const DeformableContactPoint& contact : holder.world.last_contacts(slab))
      if (contact.partner_object == capsule) smallest = std::min(smallest, contact.gap);
    if (smallest > 1e8) {
      ++roll.steps_without_contact;
      continue;
    }
    roll.deepest_gap = std::min(roll.deepest_gap, smallest);
    roll.highest_gap = std::max(roll.highest_gap, smallest);
  }
  roll.travel = static_cast<double>(capsule->getCenterOfMassPosition().x()) - x0;
  return roll;
}

TEST(FaceContactTest, CapsuleRolledOverASoftSlabStaysWithinHalfAMillimetreOfItsSurface) {
  const CapsuleRoll faces = RollCapsule(true);
  std::printf(
      "face contact: lowest %.4f deepest gap %.2e m, largest smallest gap %.2e m, %d steps without "
      "contact, rolled %.3f m\n",
      faces.lowest_bottom, faces.deepest_gap, faces.highest_gap, faces.steps_without_contact,
      faces.travel);
  EXPECT_GT(faces.deepest_gap, -5e-4);
  EXPECT_LT(faces.highest_gap, 5e-4);
  EXPECT_EQ(faces.steps_without_contact, 0);
  EXPECT_GT(faces.travel, 0.1) << "it rolls over at least one cell";
  // Point contact only: the capsule lies between the nodes and sinks into the slab.
  const CapsuleRoll points = RollCapsule(false);
  std::printf("point contact: lowest capsule point %.4f m (slab top 0.05 m)\n",
              points.lowest_bottom);
  EXPECT_LT(points.lowest_bottom, 0.05 - 5e-3);
}

}  // namespace
}  // namespace taut
