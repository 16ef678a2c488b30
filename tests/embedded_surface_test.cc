#include "plugin/embedded_surface.h"

#include <gtest/gtest.h>

#include <string>

#include "plugin/hex_voxelizer.h"
#include "plugin/obj_surface_reader.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

// Lattice node positions x = A X + b (3 num_nodes).
VecX ApplyAffine(const HexLattice& lattice, const Mat3& A, const Vec3& b) {
  VecX x(3 * lattice.nodes.size());
  for (std::size_t n = 0; n < lattice.nodes.size(); ++n)
    x.segment<3>(3 * n) = A * lattice.nodes[n] + b;
  return x;
}

// Rest node positions (3 num_nodes).
VecX RestPositions(const HexLattice& lattice) {
  return ApplyAffine(lattice, Mat3::Identity(), Vec3::Zero());
}

// A general (sheared, stretched, rotated, non-symmetric) affine map.
Mat3 SomeMatrix() {
  Mat3 A;
  A << 1.3, 0.2, -0.4, 0.1, 0.7, 0.3, 0.5, -0.2, 1.1;
  return A;
}

TEST(EmbeddedSurfaceTest, SphereInItsVoxelLatticeIsReproducedAtRestAndUnderAffineMaps) {
  const SurfaceMesh sphere = MakeIcosphereSurface(1.0, 3, Vec3(0.2, -0.1, 0.05));
  const HexLattice lattice = VoxelizeSurface(sphere, 0.25);
  const EmbeddedSurface embedded = EmbedSurface(lattice, sphere);
  ASSERT_EQ(embedded.vertices.size(), sphere.vertices.size());
  EXPECT_EQ(embedded.triangles, sphere.triangles);
  // Cells are kept by their centres, so part of the surface lies outside every hex.
  EXPECT_GT(embedded.num_extrapolated, 0);
  EXPECT_LT(embedded.num_extrapolated, static_cast<int>(sphere.vertices.size()));
  int outside_unit_cube = 0;
  for (const EmbeddedVertex& ev : embedded.vertices) {
    double sum = 0.0;
    for (double w : ev.weights) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-14);
    outside_unit_cube += ev.s.cwiseAbs().maxCoeff() > 1.0 + 1e-8;
  }
  EXPECT_EQ(outside_unit_cube, embedded.num_extrapolated);
  const std::vector<Vec3> rest = CalcEmbeddedPositions(embedded, lattice, RestPositions(lattice));
  for (std::size_t v = 0; v < rest.size(); ++v)
    EXPECT_LT((rest[v] - sphere.vertices[v]).norm(), 1e-12) << "vertex " << v;
  // Trilinear interpolation reproduces affine maps exactly, extrapolated vertices included.
  const Mat3 A = SomeMatrix();
  const Vec3 b(0.3, -1.2, 2.5);
  const std::vector<Vec3> moved =
      CalcEmbeddedPositions(embedded, lattice, ApplyAffine(lattice, A, b));
  for (std::size_t v = 0; v < moved.size(); ++v)
    EXPECT_LT((moved[v] - (A * sphere.vertices[v] + b)).norm(), 1e-12) << "vertex " << v;
  // A non-affine map is not reproduced (the check above is not vacuous).
  VecX bent = RestPositions(lattice);
  for (Eigen::Index n = 0; n < bent.size(); n += 3) bent[n] += bent[n + 1] * bent[n + 1];
  const std::vector<Vec3> curved = CalcEmbeddedPositions(embedded, lattice, bent);
  double max_error = 0.0;
  for (std::size_t v = 0; v < curved.size(); ++v) {
    const Vec3& X = sphere.vertices[v];
    max_error = std::max(max_error, std::abs(curved[v].x() - (X.x() + X.y() * X.y())));
  }
  EXPECT_GT(max_error, 1e-4);
}

TEST(EmbeddedSurfaceTest, VertexSlightlyOutsideUsesTheNearestHexWithExtrapolatedWeights) {
  // 2x2x2 box [0, 1]^3, cells of 0.5.
  const HexLattice lattice = MakeBoxHexLattice(Vec3(1, 1, 1), 2, 2, 2);
  SurfaceMesh points;
  points.source = "points";
  points.vertices = {{0.3, 0.6, 0.1},       // inside cell (0, 1, 0)
                     {1.01, 0.6, 0.2},      // just beyond x = 1: nearest centre (0.75, 0.75, 0.25)
                     {-0.02, -0.03, 1.04},  // beyond a corner: cell (0, 0, 1)
                     {0.5, 0.5, 0.5}};      // shared node: floor picks cell (1, 1, 1)
  const EmbeddedSurface embedded = EmbedSurface(lattice, points);
  EXPECT_EQ(embedded.num_extrapolated, 2);
  // MakeBoxHexLattice lists cells x fastest: cell (i, j, k) is hex i + 2 j + 4 k.
  EXPECT_EQ(embedded.vertices[0].hex, 0 + 2 * 1);
  EXPECT_EQ(embedded.vertices[1].hex, 1 + 2 * 1);
  EXPECT_EQ(embedded.vertices[2].hex, 4);
  EXPECT_EQ(embedded.vertices[3].hex, 7);
  // s = 2 (X - centre) / h: 2 (1.01 - 0.75) / 0.5 = 1.04 for vertex 1.
  EXPECT_NEAR(embedded.vertices[1].s.x(), 1.04, 1e-14);
  EXPECT_TRUE(embedded.vertices[3].s.isApprox(Vec3(-1, -1, -1), 1e-15));
  EXPECT_NEAR(embedded.vertices[3].weights[0], 1.0, 1e-15);
  // Vertex 1's weights: factor (1 - s_x) / 2 = -0.02 < 0 on the -x nodes; N_a > 1 possible too.
  double min_weight = 1.0;
  for (double w : embedded.vertices[1].weights) min_weight = std::min(min_weight, w);
  EXPECT_LT(min_weight, 0.0);
  for (const EmbeddedVertex& ev : embedded.vertices) {
    double sum = 0.0;
    for (double w : ev.weights) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
  const Mat3 A = SomeMatrix();
  const Vec3 b(-0.5, 0.25, 3.0);
  const std::vector<Vec3> moved =
      CalcEmbeddedPositions(embedded, lattice, ApplyAffine(lattice, A, b));
  for (std::size_t v = 0; v < moved.size(); ++v)
    EXPECT_LT((moved[v] - (A * points.vertices[v] + b)).norm(), 1e-13) << "vertex " << v;
}

TEST(EmbeddedSurfaceTest, IrregularLatticesAndBadSizesAreRejected) {
  HexLattice lattice = MakeBoxHexLattice(Vec3(1, 1, 1), 2, 1, 1);
  lattice.nodes[4].x() += 0.01;  // node (1, 1, 0) of the shared face
  const SurfaceMesh box = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  try {
    EmbedSurface(lattice, box);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not on the regular grid of element 0"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(EmbedSurface(HexLattice{}, box), InputError);
  EXPECT_THROW(EmbedSurface(MakeBoxHexLattice(Vec3(1, 1, 1), 1, 1, 1), SurfaceMesh{}), InputError);
  const HexLattice good = MakeBoxHexLattice(Vec3(1, 2, 3), 1, 2, 3);  // non-cubic cells work
  const EmbeddedSurface embedded = EmbedSurface(good, box);
  EXPECT_EQ(embedded.num_extrapolated, 0);
  EXPECT_THROW(CalcEmbeddedPositions(embedded, good, VecX::Zero(5)), InputError);
}

TEST(EmbeddedSurfaceTest, ObjWriterRoundTripsThroughTheObjReader) {
  const SurfaceMesh sphere = MakeIcosphereSurface(0.9, 2, Vec3(1.0 / 3, 0.0, -2.0));
  const std::string path = mesh_test::TempPath("embedded.obj");
  WriteEmbeddedSurfaceObj(path, sphere.vertices, sphere.triangles);
  const SurfaceMesh read = ReadObjSurface(path);
  ASSERT_EQ(read.vertices.size(), sphere.vertices.size());
  EXPECT_EQ(read.triangles, sphere.triangles);
  for (std::size_t v = 0; v < read.vertices.size(); ++v)
    EXPECT_LT((read.vertices[v] - sphere.vertices[v]).cwiseAbs().maxCoeff(), 1e-15) << v;
  EXPECT_THROW(WriteEmbeddedSurfaceObj(path, {Vec3::Zero()}, {{0, 1, 0}}), InputError);
  EXPECT_THROW(WriteEmbeddedSurfaceObj(mesh_test::TempPath("no/such/dir/x.obj"), sphere.vertices,
                                       sphere.triangles),
               InputError);
}

}  // namespace
}  // namespace taut
