// Bodies, start states and shape measures of the stress cells.
#pragma once

#include <btBulletDynamicsCommon.h>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/deformable_body.h"
#include "plugin/hex_lattice.h"
#include "plugin/tet_mesh.h"

namespace taut::stress {

// A box tet mesh with one interior node moved so that its flattest tets have quality
// V / (longest edge)^3 = target_quality (an undistorted Kuhn tet has 1 / (6 * 3^1.5) = 0.032).
struct SliverMesh {
  TetMesh mesh;
  int num_slivers = 0;       // tets with quality below 2 target_quality
  double min_quality = 0.0;  // smallest V / (longest edge)^3 over the mesh
};

// Cube [min_corner, min_corner + side] of n^3 Kuhn-split cells (n >= 3) with node (1, 1, 1) moved
// along a fixed generic direction until the flattest tet reaches target_quality (in (0, 0.01]).
SliverMesh MakeSliverCubeMesh(double side, int n, double target_quality, const Vec3& min_corner);

// Signed quality V / (longest edge)^3 of a tet (negative when inverted).
double CalcTetQuality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Volume measures of a tet body at positions x (3N).
struct TetVolumeStats {
  double volume_ratio = 0.0;      // signed volume sum / rest volume sum
  int inverted = 0;               // tets with signed volume <= 0
  double min_volume_ratio = 0.0;  // min over tets of V / V_rest
};
TetVolumeStats CalcTetVolumeStats(const TetMesh& mesh, const VecX& x);

// Hexes of a lattice whose map s -> x is inverted or flat (det dx/ds <= 0) at a Gauss point.
int CountInvertedHexes(const HexLattice& lattice, const VecX& x);

// A cube [min_corner, min_corner + side] of cells^3 Kuhn-split tets, or hexes, added to `world`.
DeformableBody* AddCubeBody(double side, int cells, bool hexes, const Vec3& min_corner,
                            const DeformableBodySettings& settings, DeformableWorld& world);

// Mass-weighted RMS distance between x and the rest positions after the best proper rigid
// motion (Kabsch), divided by `size` [-]. A body that stays mirrored cannot get below ~the
// mirror distance, since a proper rotation cannot undo a reflection.
double CalcShapeError(const VecX& rest, const VecX& x, const VecX& mass, double size);

// Mirrors every position (3N) through the plane through `point` with unit `normal`.
void MirrorPositions(const Vec3& point, const Vec3& normal, VecX& x);

// Sets every z of x (3N) to `z` (the body squashed flat).
void SquashPositions(double z, VecX& x);

// Centre of mass of the body at its current positions [m].
Vec3 CalcCentreOfMass(const DeformableBody& body);
// Linear momentum sum m_i v_i [kg m/s].
Vec3 CalcLinearMomentum(const DeformableBody& body);
// Angular momentum about the centre of mass sum m_i (x_i - c) x v_i [kg m^2/s].
Vec3 CalcAngularMomentum(const DeformableBody& body);

// Sets every node's velocity to the rigid motion v_c + w x (x_i - c) about the centre of mass c.
void SetRigidVelocity(const Vec3& v_c, const Vec3& w, DeformableBody& body);

// Adds a dynamic box (half extents [m], mass [kg]) centred at `centre`, owned by the holder.
btRigidBody* AddDynamicBox(const Vec3& half_extents, double mass, const Vec3& centre,
                           BulletWorldHolder& holder);

}  // namespace taut::stress
