#include "plugin/deformable_body.h"

#include <gtest/gtest.h>

#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"
#include "tests/allocation_counter.h"

namespace taut {
namespace {

std::unique_ptr<DeformableBody> MakeBeam(const Vec3& size, int nx, int ny, int nz,
                                         const Material& material, double mass_damping = 0.0) {
  DeformableBodySettings settings;
  settings.name = "beam";
  settings.material = material;
  settings.mass_damping = mass_damping;
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(size, nx, ny, nz));
  return std::make_unique<DeformableBody>(std::make_unique<TetElementModel>(mesh, material),
                                          settings);
}

// Mean z displacement of the nodes at x = L.
double TipDeflection(const DeformableBody& body, double length) {
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < body.num_nodes(); ++i) {
    const Vec3 X = body.model().rest_positions().segment<3>(3 * i);
    if (X.x() > length - 1e-9) {
      sum += body.node_position(i).z() - X.z();
      ++count;
    }
  }
  return sum / count;
}

TEST(DeformableBodyTest, LumpedMassSumsToBodyMass) {
  auto body = MakeBeam(Vec3(1, 0.2, 0.3), 4, 2, 2, Material{1e5, 0.3, 800});
  EXPECT_NEAR(body->mass().sum(), 800 * 0.06, 1e-10);
}

// Static tip deflection of a cantilever L x H x H under gravity, meshed nx x 2 x nz. Large-h
// backward-Euler steps are Newton steps of the static problem ((M + h^2 K) h v = h^2 f, h -> inf).
double StaticCantileverTip(double L, double H, int nx, int nz, const Material& material) {
  auto body = MakeBeam(Vec3(L, H, H), nx, 2, nz, material);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  for (int it = 0; it < 2; ++it) {
    body->set_v(VecX::Zero(body->x().size()));
    body->BeginStep(1e3, Vec3(0, 0, -9.81));
    body->EndStep(1e3);
  }
  return -TipDeflection(*body, L);
}

TEST(DeformableBodyTest, StaticCantileverMatchesTimoshenkoWithin3Percent) {
  // Stubby beam L/H = 5, small deflection (tip/L ~ 4e-3). nu = 0 so the clamped end has no
  // Poisson stiffening, which beam theory does not model. Linear tets are stiff in bending, so
  // the mesh is refined along the bending plane (80 x 2 x 16 cubes, 15,360 tets).
  const double L = 1.0, H = 0.2, E = 1e8, nu = 0.0, rho = 1000, g = 9.81;
  const Material material{E, nu, rho};
  // Timoshenko: q L^4/(8 E I) + q L^2/(2 kappa G A), q = rho g A, kappa = 10(1+nu)/(12+11nu).
  const double A = H * H, I = H * H * H * H / 12.0, q = rho * g * A;
  const double G = E / (2 * (1 + nu)), kappa = 10 * (1 + nu) / (12 + 11 * nu);
  const double expected = q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * kappa * G * A);
  const double coarse = StaticCantileverTip(L, H, 20, 4, material);
  const double fine = StaticCantileverTip(L, H, 80, 16, material);
  std::printf("cantilever tip: 20x2x4 %.4e m, 80x2x16 %.4e m, Timoshenko %.4e m (error %.2f %%)\n",
              coarse, fine, expected, 100 * (fine / expected - 1));
  EXPECT_NEAR(fine / expected, 1.0, 0.03);
  // Refinement moves toward theory (the coarse mesh locks and is clearly too stiff).
  EXPECT_LT(coarse, 0.9 * fine);
}

TEST(DeformableBodyTest, FreeBodyWithoutGravityNeverGainsEnergy) {
  auto body = MakeBeam(Vec3(1, 0.3, 0.3), 6, 2, 2, Material{2e4, 0.3, 1000});
  // Initial state: stretched along x, spinning about z.
  VecX x = body->x(), v = body->x();
  for (int i = 0; i < body->num_nodes(); ++i) {
    const Vec3 X = x.segment<3>(3 * i);
    x.segment<3>(3 * i) = Vec3(1.3 * X.x(), X.y(), X.z());
    v.segment<3>(3 * i) = Vec3(0, 0, 2).cross(X - Vec3(0.5, 0.15, 0.15));
  }
  body->set_x(x);
  body->set_v(v);
  double energy = body->CalcElasticEnergy() + body->CalcKineticEnergy();
  ASSERT_GT(energy, 1.0);
  for (int step = 0; step < 300; ++step) {
    body->BeginStep(1.0 / 120.0, Vec3::Zero());
    body->EndStep(1.0 / 120.0);
    const double next = body->CalcElasticEnergy() + body->CalcKineticEnergy();
    EXPECT_LE(next, energy * (1 + 1e-9)) << "step " << step;
    energy = next;
  }
}

TEST(DeformableBodyTest, FixedAndKinematicNodesFollowTheirPrescription) {
  auto body = MakeBeam(Vec3(1, 0.2, 0.2), 5, 1, 1, Material{5e4, 0.3, 1000});
  body->FixNodes({0, 1});
  const Vec3 target = body->node_position(5) + Vec3(0.0, 0.0, 0.05);
  body->SetKinematicTarget(5, target);
  const Vec3 fixed0 = body->node_position(0);
  body->BeginStep(0.01, Vec3(0, 0, -9.81));
  body->EndStep(0.01);
  EXPECT_EQ(body->node_position(0), fixed0);
  EXPECT_LT((body->node_position(5) - target).norm(), 1e-12);
  EXPECT_LT(body->node_position(3).z(), 0.0);  // free nodes fall
}

TEST(DeformableBodyTest, StepMakesNoHeapAllocationAfterTheFirst) {
  auto body = MakeBeam(Vec3(1, 0.2, 0.2), 10, 2, 2, Material{2e5, 0.3, 1000}, 1.0);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  body->BeginStep(1e-3, Vec3(0, 0, -9.81));  // first step builds the pattern
  body->EndStep(1e-3);
  testing::ScopedAllocationCounter counter;
  for (int step = 0; step < 5; ++step) {
    body->BeginStep(1e-3, Vec3(0, 0, -9.81));
    body->EndStep(1e-3);
  }
  EXPECT_EQ(counter.count(), 0u);
}

// PrepareSystem does the first step's build (pattern, symbolic factorization) at set-up: that
// step then allocates nothing, like every later one, and the trajectory is bit for bit the one of
// a body that builds in its first step.
TEST(DeformableBodyTest, PreparedSystemMakesTheFirstStepLikeTheOthers) {
  auto prepared = MakeBeam(Vec3(1, 0.2, 0.2), 10, 2, 2, Material{2e5, 0.3, 1000}, 1.0);
  auto lazy = MakeBeam(Vec3(1, 0.2, 0.2), 10, 2, 2, Material{2e5, 0.3, 1000}, 1.0);
  for (DeformableBody* body : {prepared.get(), lazy.get()})
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  EXPECT_EQ(prepared->system().num_free_dofs(), 0);
  prepared->PrepareSystem();
  EXPECT_EQ(prepared->system().num_free_dofs(), 3 * (prepared->num_nodes() - 9));
  {
    testing::ScopedAllocationCounter counter;
    prepared->BeginStep(1e-3, Vec3(0, 0, -9.81));
    prepared->EndStep(1e-3);
    EXPECT_EQ(counter.count(), 0u);
  }
  lazy->BeginStep(1e-3, Vec3(0, 0, -9.81));
  lazy->EndStep(1e-3);
  for (int step = 0; step < 5; ++step) {
    for (DeformableBody* body : {prepared.get(), lazy.get()}) {
      body->BeginStep(1e-3, Vec3(0, 0, -9.81));
      body->EndStep(1e-3);
    }
  }
  EXPECT_EQ(prepared->x(), lazy->x());
  EXPECT_NE(prepared->x(), prepared->model().rest_positions());  // the beam moved
}

TEST(DeformableBodyTest, BadInputIsRejectedWithWhatAndWhere) {
  try {
    MakeBeam(Vec3(1, 1, 1), 1, 1, 1, Material{-5.0, 0.3, 1000});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Young's modulus"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MakeBeam(Vec3(1, 1, 1), 1, 1, 1, Material{1e5, 0.5, 1000}), InputError);
  EXPECT_THROW(MakeBeam(Vec3(1, 1, 1), 1, 1, 1, Material{1e5, 0.3, 0.0}), InputError);
  auto body = MakeBeam(Vec3(1, 1, 1), 1, 1, 1, Material{1e5, 0.3, 1000});
  EXPECT_THROW(body->FixNodes({100}), InputError);
  EXPECT_THROW(body->set_x(VecX::Constant(body->x().size(), std::nan(""))), InputError);
}

TEST(DeformableBodyTest, NanDuringStepKeepsLastGoodStateAndSaysWhere) {
  auto body = MakeBeam(Vec3(1, 1, 1), 1, 1, 1, Material{1e5, 0.3, 1000});
  const VecX x0 = body->x();
  body->BeginStep(0.01, Vec3(0, 0, -9.81));
  body->mutable_v()[7] = std::nan("");
  try {
    body->EndStep(0.01);
    FAIL();
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("node 2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(body->x(), x0);
}

}  // namespace
}  // namespace taut
