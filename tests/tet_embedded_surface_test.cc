#include "plugin/tet_embedded_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "demos/scenes/scene.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/contact_surface.h"
#include "plugin/obj_surface_reader.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

// Mesh node positions x = A X + b (3 num_nodes).
VecX ApplyAffine(const TetMesh& mesh, const Mat3& A, const Vec3& b) {
  VecX x(3 * mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) x.segment<3>(3 * n) = A * mesh.nodes[n] + b;
  return x;
}

VecX RestPositions(const TetMesh& mesh) {
  return ApplyAffine(mesh, Mat3::Identity(), Vec3::Zero());
}

// A general (sheared, stretched, rotated, non-symmetric) affine map.
Mat3 SomeMatrix() {
  Mat3 A;
  A << 1.3, 0.2, -0.4, 0.1, 0.7, 0.3, 0.5, -0.2, 1.1;
  return A;
}

double SumOf(const std::array<double, 4>& w) { return w[0] + w[1] + w[2] + w[3]; }

// The unit cube in 6 x 6 x 6 cubes (1296 tets) and a sphere strictly inside it, off-centre so
// that no vertex lies on a tet face.
TetMesh MakeUnitBoxMesh() { return MakeBoxTetMesh(Vec3(1, 1, 1), 6, 6, 6); }
SurfaceMesh MakeInnerSphere() { return MakeIcosphereSurface(0.4, 3, Vec3(0.5013, 0.4987, 0.5031)); }

// Mean tet edge length of MakeBoxTetMesh cubes of edge h: each Kuhn tet has 3 cube edges, 2 face
// diagonals and the cube diagonal, (3 + 2 sqrt 2 + sqrt 3) h / 6.
double MeanBoxTetEdge(double h) { return (3.0 + 2.0 * std::sqrt(2.0) + std::sqrt(3.0)) * h / 6.0; }

TEST(TetEmbeddedSurfaceTest, InteriorVerticesHaveNonNegativeWeightsAndTheirRestPositions) {
  const TetMesh mesh = MakeUnitBoxMesh();
  const SurfaceMesh sphere = MakeInnerSphere();
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, sphere);
  ASSERT_EQ(embedded.vertices.size(), sphere.vertices.size());
  EXPECT_EQ(embedded.triangles, sphere.triangles);
  EXPECT_EQ(embedded.num_extrapolated, 0);
  for (std::size_t v = 0; v < embedded.vertices.size(); ++v) {
    const TetEmbeddedVertex& ev = embedded.vertices[v];
    EXPECT_NEAR(SumOf(ev.weights), 1.0, 1e-14) << "vertex " << v;
    for (double w : ev.weights) {
      EXPECT_GE(w, 0.0) << "vertex " << v;
      EXPECT_LE(w, 1.0) << "vertex " << v;
    }
    EXPECT_EQ(ev.outside_distance, 0.0);
  }
  const std::vector<Vec3> rest = CalcTetEmbeddedPositions(embedded, mesh, RestPositions(mesh));
  for (std::size_t v = 0; v < rest.size(); ++v)
    EXPECT_LT((rest[v] - sphere.vertices[v]).norm(), 1e-12) << "vertex " << v;
}

TEST(TetEmbeddedSurfaceTest, FinerBoxSurfaceOnTetFacesAndOnTheBoundaryIsReproducedAtRest) {
  // The finer box's vertices lie on tet faces, edges and nodes (x = 0.5 is a grid plane) and its
  // top face on the mesh's boundary z = 1: all inside, up to rounding.
  const TetMesh mesh = MakeUnitBoxMesh();
  const SurfaceMesh box = MakeBoxSurface(Vec3(0.8, 0.8, 0.9), 8, 8, 9, Vec3(0.1, 0.1, 0.1));
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, box);
  EXPECT_EQ(embedded.num_extrapolated, 0);
  for (const TetEmbeddedVertex& ev : embedded.vertices) {
    EXPECT_NEAR(SumOf(ev.weights), 1.0, 1e-14);
    for (double w : ev.weights) EXPECT_GE(w, -1e-15);
  }
  const std::vector<Vec3> rest = CalcTetEmbeddedPositions(embedded, mesh, RestPositions(mesh));
  for (std::size_t v = 0; v < rest.size(); ++v)
    EXPECT_LT((rest[v] - box.vertices[v]).norm(), 1e-12) << "vertex " << v;
}

TEST(TetEmbeddedSurfaceTest, AffineMapOfTheNodesMovesEveryVertexExactly) {
  const TetMesh mesh = MakeUnitBoxMesh();
  SurfaceMesh sphere = MakeInnerSphere();
  sphere.vertices.push_back(Vec3(0.3, 0.7, 1.004));  // slightly outside: extrapolated
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, sphere);
  EXPECT_EQ(embedded.num_extrapolated, 1);
  const Mat3 A = SomeMatrix();
  const Vec3 b(0.3, -1.2, 2.5);
  const std::vector<Vec3> moved = CalcTetEmbeddedPositions(embedded, mesh, ApplyAffine(mesh, A, b));
  for (std::size_t v = 0; v < moved.size(); ++v)
    EXPECT_LT((moved[v] - (A * sphere.vertices[v] + b)).norm(), 1e-12) << "vertex " << v;
  // A non-affine map is not reproduced (the check above is not vacuous).
  VecX bent = RestPositions(mesh);
  for (Eigen::Index n = 0; n < bent.size(); n += 3) bent[n] += bent[n + 1] * bent[n + 1];
  const std::vector<Vec3> curved = CalcTetEmbeddedPositions(embedded, mesh, bent);
  double max_error = 0.0;
  for (std::size_t v = 0; v < curved.size(); ++v) {
    const Vec3& X = sphere.vertices[v];
    max_error = std::max(max_error, std::abs(curved[v].x() - (X.x() + X.y() * X.y())));
  }
  EXPECT_GT(max_error, 1e-4);
}

TEST(TetEmbeddedSurfaceTest, VertexSlightlyOutsideUsesTheNearestTetWithExtrapolatedWeights) {
  // [0, 1]^3 in 2 x 2 x 2 cubes of 0.5: tolerance 0.1 x mean edge = 0.0630 m.
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 2, 2, 2);
  SurfaceMesh points;
  points.source = "points";
  points.vertices = {{0.3, 0.6, 0.1},        // inside
                     {0.4, 0.7, 1.01},       // 0.01 above the top face
                     {-0.02, -0.03, -0.04},  // beyond the corner node 0: sqrt(29) cm away
                     {1.0, 0.5, 0.25}};      // on the boundary face x = 1: inside
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, points);
  EXPECT_EQ(embedded.num_extrapolated, 2);
  EXPECT_EQ(embedded.vertices[0].outside_distance, 0.0);
  EXPECT_NEAR(embedded.vertices[1].outside_distance, 0.01, 1e-15);
  EXPECT_NEAR(embedded.vertices[2].outside_distance, std::sqrt(29.0) * 0.01, 1e-15);
  EXPECT_EQ(embedded.vertices[3].outside_distance, 0.0);
  // The corner vertex extrapolates from a tet at node 0 (weight > 1 there, negative elsewhere).
  const auto& corner_tet = mesh.tets[embedded.vertices[2].tet];
  EXPECT_NE(std::find(corner_tet.begin(), corner_tet.end(), 0), corner_tet.end());
  for (int v : {1, 2}) {
    const auto& w = embedded.vertices[v].weights;
    EXPECT_LT(*std::min_element(w.begin(), w.end()), 0.0) << "vertex " << v;
    EXPECT_NEAR(SumOf(w), 1.0, 1e-14) << "vertex " << v;
  }
  const std::vector<Vec3> rest = CalcTetEmbeddedPositions(embedded, mesh, RestPositions(mesh));
  const Mat3 A = SomeMatrix();
  const Vec3 b(-0.5, 0.25, 3.0);
  const std::vector<Vec3> moved = CalcTetEmbeddedPositions(embedded, mesh, ApplyAffine(mesh, A, b));
  for (std::size_t v = 0; v < points.vertices.size(); ++v) {
    EXPECT_LT((rest[v] - points.vertices[v]).norm(), 1e-14) << "vertex " << v;
    EXPECT_LT((moved[v] - (A * points.vertices[v] + b)).norm(), 1e-13) << "vertex " << v;
  }
}

TEST(TetEmbeddedSurfaceTest, VertexFarOutsideIsAnErrorNamingItsIndexAndDistance) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 2, 2, 2);
  SurfaceMesh points;
  points.source = "skin.obj";
  points.vertices = {{0.3, 0.6, 0.1}, {0.5, 0.5, 0.5}, {0.5, 0.25, 1.3}};
  try {
    EmbedSurfaceInTets(mesh, points);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const char* part : {"skin.obj: vertex 2 ", " is 0.3 m outside tet mesh", "0.063004 m"})
      EXPECT_NE(message.find(part), std::string::npos) << part << " in: " << message;
  }
  // The same vertex with a larger tolerance (in mean edge lengths) is extrapolated.
  EXPECT_EQ(EmbedSurfaceInTets(mesh, points, 0.3 / MeanBoxTetEdge(0.5) + 1e-6).num_extrapolated, 1);
  EXPECT_THROW(EmbedSurfaceInTets(mesh, points, 0.3 / MeanBoxTetEdge(0.5) - 1e-6), InputError);
  // A vertex that is exactly on the mesh needs no tolerance.
  points.vertices[2] = Vec3(0.5, 0.25, 1.0);
  EXPECT_EQ(EmbedSurfaceInTets(mesh, points, 0.0).num_extrapolated, 0);
}

TEST(TetEmbeddedSurfaceTest, BadInputIsRejected) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1);
  const SurfaceMesh box = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  EXPECT_THROW(EmbedSurfaceInTets(TetMesh{}, box), InputError);
  EXPECT_THROW(EmbedSurfaceInTets(mesh, SurfaceMesh{}), InputError);
  EXPECT_THROW(EmbedSurfaceInTets(mesh, box, -0.1), InputError);
  SurfaceMesh broken = box;
  broken.triangles[3][1] = 99;
  EXPECT_THROW(EmbedSurfaceInTets(mesh, broken), InputError);
  broken = box;
  broken.vertices[2].y() = std::nan("");
  EXPECT_THROW(EmbedSurfaceInTets(mesh, broken), InputError);
  TetMesh inverted = mesh;
  std::swap(inverted.tets[0][0], inverted.tets[0][1]);
  EXPECT_THROW(EmbedSurfaceInTets(inverted, box), InputError);
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, box);
  EXPECT_THROW(CalcTetEmbeddedPositions(embedded, mesh, VecX::Zero(5)), InputError);
}

TEST(TetEmbeddedSurfaceTest, ContactSurfaceHasFourNodePointsAtTheVertices) {
  const TetMesh mesh = MakeUnitBoxMesh();
  const SurfaceMesh sphere = MakeInnerSphere();
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, sphere);
  const ContactSurface contact = MakeTetEmbeddedContactSurface(mesh, embedded);
  EXPECT_FALSE(contact.node_triangles);
  EXPECT_EQ(contact.triangles, sphere.triangles);
  ASSERT_EQ(contact.points.size(), sphere.vertices.size());
  const VecX x = ApplyAffine(mesh, SomeMatrix(), Vec3(1, 2, 3));
  const std::vector<Vec3> points = CalcContactPointPositions(contact, x);
  const std::vector<Vec3> vertices = CalcTetEmbeddedPositions(embedded, mesh, x);
  for (std::size_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(contact.points[v].num_nodes, 4);
    EXPECT_EQ(points[v], vertices[v]) << "vertex " << v;  // the same sum, bit for bit
  }
}

// A scene holding one tet body (the unit box mesh) with the inner sphere embedded in it.
class TetBoxScene : public Scene {
 public:
  TetBoxScene() {
    body_ = world().AddTetBody(MakeUnitBoxMesh(), MakeSceneBodySettings("tet_box", 1e6, 1000.0));
    AttachEmbeddedSurface(0, MakeInnerSphere());
  }
  void WriteFigures(nlohmann::json& /*figures*/) const override {}
  DeformableBody& body() { return *body_; }

 private:
  DeformableBody* body_ = nullptr;
};

TEST(TetEmbeddedSurfaceTest, PerFrameObjHoldsTheDeformedEmbeddedVertices) {
  TetBoxScene scene;
  ASSERT_EQ(scene.num_embedded_surfaces(), 1);
  const TetMesh mesh = MakeUnitBoxMesh();
  const SurfaceMesh sphere = MakeInnerSphere();
  const Mat3 A = SomeMatrix();
  const Vec3 b(0.1, -0.2, 0.3);
  scene.body().set_x(ApplyAffine(mesh, A, b));
  const std::string dir = std::filesystem::path(mesh_test::TempPath("frame.txt")).parent_path();
  scene.WriteVtkFrame(dir, 3);
  const SurfaceMesh written = ReadObjSurface(dir + "/tet_box_surface_000003.obj");
  EXPECT_EQ(written.triangles, sphere.triangles);
  const std::vector<Vec3> expected = scene.CalcEmbeddedSurfacePositions(0);
  ASSERT_EQ(written.vertices.size(), expected.size());
  for (std::size_t v = 0; v < expected.size(); ++v) {
    EXPECT_EQ(written.vertices[v], expected[v]) << "vertex " << v;  // shortest round-trip text
    EXPECT_LT((written.vertices[v] - (A * sphere.vertices[v] + b)).norm(), 1e-12) << v;
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/tet_box_surface_000003.vtk"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/tet_box_surface.pvd"));
}

TEST(TetEmbeddedSurfaceTest, LargeSurfaceEmbedsInAboutLinearTime) {
  // 163,842 vertices in 10,368 tets; a search over every tet would be 1.7e9 tests.
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 12, 12, 12);
  const SurfaceMesh sphere = MakeIcosphereSurface(0.45, 7, Vec3(0.5013, 0.4987, 0.5031));
  const auto start = std::chrono::steady_clock::now();
  const TetEmbeddedSurface embedded = EmbedSurfaceInTets(mesh, sphere);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("embedded %zu vertices in %zu tets in %.3f s\n", sphere.vertices.size(),
              mesh.tets.size(), seconds);
  EXPECT_EQ(embedded.num_extrapolated, 0);
  const std::vector<Vec3> rest = CalcTetEmbeddedPositions(embedded, mesh, RestPositions(mesh));
  double max_error = 0.0;
  for (std::size_t v = 0; v < rest.size(); ++v)
    max_error = std::max(max_error, (rest[v] - sphere.vertices[v]).norm());
  EXPECT_LT(max_error, 1e-12);
}

}  // namespace
}  // namespace taut
