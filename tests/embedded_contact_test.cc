// Hex and tet bodies touching through a surface embedded in their lattice or mesh: each surface
// vertex is a contact point with 8 trilinear or 4 barycentric weights, so the surface (not the
// blocky lattice or the coarse tet boundary) rests on the ground.
#include <gtest/gtest.h>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/contact_surface.h"
#include "plugin/hex_lattice.h"
#include "plugin/surface_mesh.h"

namespace taut {
namespace {

// Lowest embedded-surface vertex and lowest lattice node after dropping a 0.4 m lattice whose
// embedded box surface reaches 5 cm below the lattice (extrapolated weights).
void DropBlock(bool embedded_contact, double& surface_bottom, double& lattice_bottom) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  const HexLattice lattice = MakeBoxHexLattice(Vec3(0.4, 0.4, 0.4), 2, 2, 2, Vec3(-0.2, -0.2, 0.1));
  const SurfaceMesh surface = MakeBoxSurface(Vec3(0.4, 0.4, 0.45), 2, 2, 2, Vec3(-0.2, -0.2, 0.05));
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {1e6, 0.3, 500.0};
  settings.mass_damping = 5.0;
  DeformableBody* block = holder.world.AddHexBody(lattice, settings);
  if (embedded_contact) holder.world.SetContactSurface(block, surface);
  for (int i = 0; i < 240; ++i) holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  const ContactSurface contact =
      MakeEmbeddedContactSurface(lattice, EmbedSurface(lattice, surface));
  surface_bottom = HUGE_VAL;
  for (const ContactPoint& p : contact.points)
    surface_bottom = std::min(surface_bottom, CalcContactPointPosition(p, block->x()).z());
  lattice_bottom = HUGE_VAL;
  for (int i = 0; i < block->num_nodes(); ++i)
    lattice_bottom = std::min(lattice_bottom, block->node_position(i).z());
}

TEST(EmbeddedContactTest, EmbeddedSurfaceRestsOnTheGroundInsteadOfTheLattice) {
  double surface_with, lattice_with, surface_without, lattice_without;
  DropBlock(true, surface_with, lattice_with);
  DropBlock(false, surface_without, lattice_without);
  std::printf(
      "embedded contact: surface bottom %.2e m, lattice bottom %.4f m; lattice contact: "
      "surface bottom %.4f m, lattice bottom %.2e m\n",
      surface_with, lattice_with, surface_without, lattice_without);
  EXPECT_NEAR(surface_with, 0.0, 1e-4);       // the surface touches the ground
  EXPECT_NEAR(lattice_with, 0.05, 5e-3);      // carried 5 cm up by it
  EXPECT_NEAR(lattice_without, 0.0, 1e-4);    // the default: the lattice touches
  EXPECT_NEAR(surface_without, -0.05, 5e-3);  // and the surface hangs through the ground
}

// Lowest embedded-surface vertex and lowest tet node after dropping a 0.4 m tet block whose
// embedded box surface starts 5 cm above the block's bottom (4-node barycentric points).
void DropTetBlock(bool embedded_contact, double& surface_bottom, double& mesh_bottom) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  const TetMesh mesh = MakeBoxTetMesh(Vec3(0.4, 0.4, 0.4), 4, 4, 4, Vec3(-0.2, -0.2, 0.1));
  const SurfaceMesh surface = MakeBoxSurface(Vec3(0.4, 0.4, 0.35), 4, 4, 4, Vec3(-0.2, -0.2, 0.15));
  DeformableBodySettings settings;
  settings.name = "tet block";
  settings.material = {1e6, 0.3, 500.0};
  settings.mass_damping = 5.0;
  DeformableBody* block = holder.world.AddTetBody(mesh, settings);
  if (embedded_contact) holder.world.SetContactSurface(block, surface);
  for (int i = 0; i < 240; ++i) holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  const ContactSurface contact =
      MakeTetEmbeddedContactSurface(mesh, EmbedSurfaceInTets(mesh, surface));
  surface_bottom = HUGE_VAL;
  for (const Vec3& p : CalcContactPointPositions(contact, block->x()))
    surface_bottom = std::min(surface_bottom, p.z());
  mesh_bottom = HUGE_VAL;
  for (int i = 0; i < block->num_nodes(); ++i)
    mesh_bottom = std::min(mesh_bottom, block->node_position(i).z());
}

TEST(EmbeddedContactTest, TetBodyRestsOnItsEmbeddedSurfaceInsteadOfItsBoundary) {
  double surface_with, mesh_with, surface_without, mesh_without;
  DropTetBlock(true, surface_with, mesh_with);
  DropTetBlock(false, surface_without, mesh_without);
  std::printf(
      "tet embedded contact: surface bottom %.2e m, mesh bottom %.4f m; boundary contact: "
      "surface bottom %.4f m, mesh bottom %.2e m\n",
      surface_with, mesh_with, surface_without, mesh_without);
  EXPECT_NEAR(surface_with, 0.0, 1e-4);      // the surface touches the ground
  EXPECT_NEAR(mesh_with, -0.05, 5e-3);       // the mesh's bottom hangs through it
  EXPECT_NEAR(mesh_without, 0.0, 1e-4);      // the default: the tet boundary touches
  EXPECT_NEAR(surface_without, 0.05, 5e-3);  // and the surface floats above the ground
}

TEST(EmbeddedContactTest, SetContactSurfaceOutsideATetBodyNamesTheBodyAndTheVertex) {
  BulletWorldHolder holder;
  DeformableBodySettings settings;
  settings.name = "tets";
  settings.material = {1e6, 0.3, 500.0};
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  mesh.tets = {{1, 0, 2, 3}};
  DeformableBody* body = holder.world.AddTetBody(mesh, settings);
  SurfaceMesh box = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);  // corner (1, 1, 1) is far outside
  box.source = "box";
  try {
    holder.world.SetContactSurface(body, box);
    FAIL() << "the box does not fit in the tet";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("body 'tets'"), std::string::npos) << message;
    EXPECT_NE(message.find("box: vertex "), std::string::npos) << message;
    EXPECT_NE(message.find(" m outside tet mesh"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace taut
