#include "plugin/finger_mesher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace taut {
namespace {

// Sum of the tets' rest volumes [m^3].
double CalcMeshVolume(const TetMesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.tets)
    volume +=
        CalcTetSignedVolume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
  return volume;
}

TEST(FingerMesherTest, CapsuleDistanceValuesAndGradientMatchFiniteDifferences) {
  const std::vector<Capsule> capsules = {{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5},
                                         {Vec3(1, 0, 0), Vec3(1, 2, 0), 0.25}};
  // On the first axis: -radius; beyond the first cap along -x: distance to the cap.
  EXPECT_NEAR(CalcCapsuleUnionDistance(capsules, Vec3(0.3, 0, 0)), -0.5, 1e-15);
  EXPECT_NEAR(CalcCapsuleUnionDistance(capsules, Vec3(-2, 0, 0)), 1.5, 1e-15);
  // Near the second segment's far end: that capsule is the nearer surface.
  EXPECT_NEAR(CalcCapsuleUnionDistance(capsules, Vec3(1, 2.75, 0)), 0.5, 1e-15);
  const double h = 1e-6;
  for (const Vec3& p :
       {Vec3(0.4, 0.7, -0.3), Vec3(-0.6, 0.2, 0.1), Vec3(1.3, 1.5, 0.2), Vec3(0.2, 0.1, 0.05)}) {
    Vec3 gradient;
    CalcCapsuleUnionDistance(capsules, p, &gradient);
    Vec3 fd;
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = h * Vec3::Unit(k);
      fd[k] =
          (CalcCapsuleUnionDistance(capsules, p + e) - CalcCapsuleUnionDistance(capsules, p - e)) /
          (2.0 * h);
    }
    EXPECT_GT(gradient.norm(), 0.5);
    EXPECT_LT((gradient - fd).norm(), 1e-8) << p.transpose();
  }
}

TEST(FingerMesherTest, SingleCapsuleMeshIsValidRoundAndOfTheRightVolume) {
  const Capsule capsule{Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.02};
  CapsuleMeshSettings settings;
  settings.cell_size = Vec3::Constant(0.005);
  const TetMesh mesh = MakeCapsuleUnionTetMesh({capsule}, settings);
  EXPECT_NO_THROW(ValidateTetMesh(mesh));
  // Boundary nodes on the surface, the others inside.
  const std::vector<int> boundary = CalcBoundaryNodes(mesh);
  std::vector<bool> on_boundary(mesh.nodes.size(), false);
  for (int node : boundary) on_boundary[node] = true;
  for (size_t i = 0; i < mesh.nodes.size(); ++i) {
    const double phi = CalcCapsuleUnionDistance({capsule}, mesh.nodes[i]);
    if (on_boundary[i]) {
      EXPECT_NEAR(phi, 0.0, 1e-12) << i;
    } else {
      EXPECT_LT(phi, 0.0) << i;
    }
  }
  // An inscribed polyhedron of the capsule: a little smaller, within 8 %.
  const double exact = M_PI * 0.02 * 0.02 * 0.1 + 4.0 / 3.0 * M_PI * std::pow(0.02, 3);
  EXPECT_LT(CalcMeshVolume(mesh), exact);
  EXPECT_GT(CalcMeshVolume(mesh), 0.92 * exact);
}

TEST(FingerMesherTest, UnsnappedMeshIsTheConformingVoxelSet) {
  // Without snapping the boundary is made of whole cell faces, two triangles each, every edge
  // shared by two boundary triangles (closed); a non-conforming split would leave inner faces.
  CapsuleMeshSettings settings;
  settings.snap_boundary = false;
  const TetMesh mesh = MakeCapsuleUnionTetMesh(MakeFingerCapsules(), settings);
  ASSERT_EQ(mesh.tets.size() % 6, 0u);
  const Vec3 cell(0.07 / 7, 0.018 / 3, 0.018 / 3);
  EXPECT_NEAR(CalcMeshVolume(mesh), mesh.tets.size() / 6 * cell.prod(), 1e-15);
  std::map<std::pair<int, int>, int> edges;
  for (const Triangle& t : CalcBoundaryFaces(mesh))
    for (int k = 0; k < 3; ++k) ++edges[std::minmax(t[k], t[(k + 1) % 3])];
  for (const auto& [edge, count] : edges) EXPECT_EQ(count, 2);
}

TEST(FingerMesherTest, FingerHasThreePhalangesAndAboutThePapersTetCount) {
  const std::vector<Capsule> finger = MakeFingerCapsules(0.07);
  ASSERT_EQ(finger.size(), 3u);
  EXPECT_NEAR(finger.front().a.x() - finger.front().radius, 0.0, 1e-15);
  EXPECT_NEAR(finger.back().b.x() + finger.back().radius, 0.07, 1e-15);
  EXPECT_GT(finger[0].radius, finger[1].radius);
  EXPECT_GT(finger[1].radius, finger[2].radius);
  const TetMesh mesh = MakeCapsuleUnionTetMesh(finger);
  EXPECT_NEAR(static_cast<double>(mesh.tets.size()), 347.0, 50.0);  // paper A: 347 tets
}

TEST(FingerMesherTest, BadInputThrows) {
  const Capsule good{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.1};
  EXPECT_THROW(MakeCapsuleUnionTetMesh({}), InputError);
  EXPECT_THROW(MakeCapsuleUnionTetMesh({{Vec3(0, 0, 0), Vec3(1, 0, 0), -0.1}}), InputError);
  EXPECT_THROW(MakeCapsuleUnionTetMesh({{Vec3(NAN, 0, 0), Vec3(1, 0, 0), 0.1}}), InputError);
  CapsuleMeshSettings settings;
  settings.cell_size = Vec3(0.1, 0.0, 0.1);
  EXPECT_THROW(MakeCapsuleUnionTetMesh({good}, settings), InputError);
  settings.cell_size = Vec3::Constant(0.05);
  settings.keep_offset = 1.5;
  EXPECT_THROW(MakeCapsuleUnionTetMesh({good}, settings), InputError);
  EXPECT_THROW(MakeFingerCapsules(-0.07), InputError);
}

}  // namespace
}  // namespace taut
