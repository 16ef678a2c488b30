// Installed-package check: a cantilever beam clamped at x = 0 must sag under gravity, keep its
// clamped nodes in place and stay finite. Returns 0 on success, 1 otherwise. Includes only the
// public headers <taut/NAME.h> (cmake/TautPublicHeaders.cmake), as a user would.
#include <btBulletDynamicsCommon.h>
#include <taut/box_tet_mesher.h>
#include <taut/deformable_world.h>

#include <cmath>
#include <cstdio>
#include <exception>

namespace {

constexpr double kLength = 1.0;

// Mean displacement of the nodes whose rest x is within 1e-9 of x_target.
taut::Vec3 CalcMeanDisplacement(const Eigen::VectorXd& x0, const Eigen::VectorXd& x, int n,
                                double x_target) {
  taut::Vec3 sum = taut::Vec3::Zero();
  int count = 0;
  for (int i = 0; i < n; ++i) {
    if (std::abs(x0[3 * i] - x_target) > 1e-9) continue;
    sum += x.segment<3>(3 * i) - x0.segment<3>(3 * i);
    ++count;
  }
  return count > 0 ? taut::Vec3(sum / count) : taut::Vec3::Zero();
}

// Builds the beam scene, steps it one second and checks the result.
int Run() {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  taut::DeformableWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, 0, -9.81));

  taut::DeformableBodySettings settings;
  settings.material.youngs_modulus = 1e5;
  settings.material.poisson_ratio = 0.3;
  settings.material.density = 1000;
  taut::DeformableBody* body =
      world.AddTetBody(taut::MakeBoxTetMesh(taut::Vec3(kLength, 0.2, 0.2), 10, 2, 2), settings);
  body->FixNodesWhere([](const taut::Vec3& X) { return X.x() < 1e-9; });

  const int n = body->num_nodes();
  const Eigen::VectorXd x0 = body->x();
  for (int i = 0; i < 60; ++i) world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
  const Eigen::VectorXd& x = body->x();

  const taut::Vec3 tip = CalcMeanDisplacement(x0, x, n, kLength);
  const taut::Vec3 root = CalcMeanDisplacement(x0, x, n, 0.0);
  std::printf("taut_consumer: %d nodes, tip displacement (%.6f, %.6f, %.6f) m, |root| %.3g m\n", n,
              tip.x(), tip.y(), tip.z(), root.norm());

  bool ok = true;
  if (!x.allFinite()) {
    std::printf("FAIL: node positions are not finite\n");
    ok = false;
  }
  if (!(tip.z() < -1e-3)) {
    std::printf("FAIL: the tip did not sag under gravity\n");
    ok = false;
  }
  if (!(tip.norm() < 2 * kLength)) {
    std::printf("FAIL: the tip moved more than twice the beam length (blow-up)\n");
    ok = false;
  }
  if (!(root.norm() < 1e-6)) {
    std::printf("FAIL: the clamped nodes moved\n");
    ok = false;
  }
  return ok ? 0 : 1;
}

}  // namespace

int main() {
  try {
    return Run();
  } catch (const std::exception& e) {
    std::printf("FAIL: exception: %s\n", e.what());
    return 1;
  }
}
