// Coulomb friction of a soft block on a real incline (a tilted static plane): it sticks below
// tan(theta) = mu and slides above it with a = g (sin theta - mu cos theta) (docs/math.md §5.5
// friction rows on the disk).
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "bullet_bridge/eigen_bullet.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kStep = 1.0 / 240.0;
constexpr double kMu = 0.5;  // body 0.5 x plane 1.0 (the product, Bullet's default combiner)

// A 0.1 m soft cube resting on a plane through the origin tilted by theta about y (downhill is
// +x'), mesh axes aligned with the slope.
struct BlockOnIncline {
  BulletWorldHolder holder;
  DeformableBody* block = nullptr;
  Vec3 downhill;

  // Body friction body_mu on a plane of friction plane_mu (combined: their product).
  explicit BlockOnIncline(double theta_deg, double body_mu = kMu, double plane_mu = 1.0) {
    const double theta = theta_deg * M_PI / 180.0;
    const Vec3 normal(std::sin(theta), 0.0, std::cos(theta));
    downhill = Vec3(std::cos(theta), 0.0, -std::sin(theta));
    auto plane = std::make_unique<btStaticPlaneShape>(ToBullet(normal), 0);
    holder.AddRigidBody(std::move(plane), 0.0, btVector3(0, 0, 0), plane_mu);
    DeformableBodySettings settings;
    settings.name = "block";
    settings.material = {1e6, 0.3, 1000.0};
    settings.friction = body_mu;
    TetMesh mesh = MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 2, 2, 2, Vec3(-0.05, -0.05, 1e-4));
    // Rotate the resting block onto the slope: x -> downhill, z -> normal.
    Mat3 rotation;
    rotation << downhill, Vec3::UnitY(), normal;
    for (Vec3& node : mesh.nodes) node = rotation * node;
    block = holder.world.AddTetBody(mesh, settings);
  }
  // Mass-weighted mean velocity along the slope [m/s].
  double CalcSlopeVelocity() const {
    double p = 0.0;
    for (int i = 0; i < block->num_nodes(); ++i)
      p += block->mass()[i] * downhill.dot(block->v().segment<3>(3 * i));
    return p / block->mass().sum();
  }
  // Mean position along the slope [m].
  double CalcSlopePosition() const {
    double s = 0.0;
    for (int i = 0; i < block->num_nodes(); ++i) s += downhill.dot(block->node_position(i));
    return s / block->num_nodes();
  }
  void Run(int steps) {
    for (int i = 0; i < steps; ++i) holder.world.stepSimulation(kStep, 1, kStep);
  }
};

TEST(InclineFrictionTest, SticksBelowTheFrictionAngleAndSlidesAboveItWithinTwoDegrees) {
  // Friction angle atan(0.5) = 26.57 deg: test 2 degrees either side.
  const double critical = std::atan(kMu) * 180.0 / M_PI;
  BlockOnIncline below(critical - 2.0), above(critical + 2.0);
  const double s_below = below.CalcSlopePosition(), s_above = above.CalcSlopePosition();
  below.Run(120);
  above.Run(120);
  const double moved_below = below.CalcSlopePosition() - s_below;
  const double moved_above = above.CalcSlopePosition() - s_above;
  std::printf("friction angle %.2f deg: at -2 deg moved %.2e m, at +2 deg moved %.4f m in 0.5 s\n",
              critical, moved_below, moved_above);
  // Above: a = g (sin - mu cos) = 0.31 m/s^2 -> ~3.9 cm in 0.5 s; below: elastic settling only.
  EXPECT_LT(std::abs(moved_below), 1e-3);
  EXPECT_GT(moved_above, 0.02);
}

TEST(InclineFrictionTest, SlidingAccelerationMatchesCoulomb) {
  const double theta_deg = 35.0, theta = theta_deg * M_PI / 180.0;
  BlockOnIncline incline(theta_deg);
  incline.Run(48);  // 0.2 s: contact established, sliding
  const double v0 = incline.CalcSlopeVelocity();
  incline.Run(72);  // 0.3 s more
  const double measured = (incline.CalcSlopeVelocity() - v0) / (72 * kStep);
  const double expected = 9.81 * (std::sin(theta) - kMu * std::cos(theta));
  std::printf("35 deg, mu 0.5: a = %.4f m/s^2, Coulomb %.4f m/s^2 (%.2f %%)\n", measured, expected,
              100.0 * (measured / expected - 1.0));
  EXPECT_NEAR(measured, expected, 0.05 * expected);
}

TEST(InclineFrictionTest, CoefficientIsTheProductOfTheBodysAndTheObjectsFriction) {
  // mu = settings.friction x btCollisionObject::getFriction(): 1.0 x 0.5 and 0.8 x 0.625 slide
  // like 0.5 x 1.0 (a = g (sin - 0.5 cos) at 35 deg); 1.0 x 1.0 (mu = 1 > tan 35 deg) sticks.
  const double theta_deg = 35.0, theta = theta_deg * M_PI / 180.0;
  const double expected = 9.81 * (std::sin(theta) - 0.5 * std::cos(theta));
  for (const auto& [body_mu, plane_mu] : {std::pair{1.0, 0.5}, std::pair{0.8, 0.625}}) {
    BlockOnIncline incline(theta_deg, body_mu, plane_mu);
    incline.Run(48);
    const double v0 = incline.CalcSlopeVelocity();
    incline.Run(72);
    const double measured = (incline.CalcSlopeVelocity() - v0) / (72 * kStep);
    std::printf("35 deg, body %.3f x plane %.3f: a = %.4f m/s^2, Coulomb (mu 0.5) %.4f m/s^2\n",
                body_mu, plane_mu, measured, expected);
    EXPECT_NEAR(measured, expected, 0.05 * expected);
  }
  BlockOnIncline sticking(theta_deg, 1.0, 1.0);
  const double start = sticking.CalcSlopePosition();
  sticking.Run(120);
  EXPECT_LT(std::abs(sticking.CalcSlopePosition() - start), 1e-3);
}

}  // namespace
}  // namespace taut
