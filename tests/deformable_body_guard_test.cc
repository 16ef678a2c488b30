// Stage-boundary guards of DeformableBody: a non-finite force or velocity, or an exploding speed,
// throws SimulationError naming body, element or node and stage, with x, v back at the step start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>

#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kStep = 0.01;
const Vec3 kGravity(0, 0, -9.81);

// A 0.5 m soft cube of 2 x 2 x 2 Kuhn-split cells (27 nodes, node 13 in the middle) named "cube",
// already moving: small random displacements and velocities, so "the step-start state" is not the
// rest state.
std::unique_ptr<DeformableBody> MakeMovingCube(double max_speed = 1e3) {
  DeformableBodySettings settings;
  settings.name = "cube";
  settings.material = {2e4, 0.3, 800.0};
  settings.max_speed = max_speed;
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(0.5, 0.5, 0.5), 2, 2, 2));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX x = body->x(), v = body->v();
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    x[i] += 0.01 * u(rng);
    v[i] = 0.2 * u(rng);
  }
  body->set_x(x);
  body->set_v(v);
  return body;
}

// Runs BeginStep (and EndStep when it returns) and returns the SimulationError message; fails the
// test when nothing throws.
std::string StepAndCatch(DeformableBody& body) {
  try {
    body.BeginStep(kStep, kGravity);
    body.EndStep(kStep);
  } catch (const SimulationError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the step did not throw SimulationError";
  return "";
}

// Expects every part in the message.
void ExpectMentions(const std::string& message, std::initializer_list<const char*> parts) {
  for (const char* part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << message << "\n  expected: " << part;
}

// The number following `word` in message, or -1.
int NumberAfter(const std::string& message, const std::string& word) {
  const std::size_t at = message.find(word);
  int value = -1;
  if (at != std::string::npos) std::sscanf(message.c_str() + at + word.size(), "%d", &value);
  return value;
}

TEST(DeformableBodyGuardTest, OverflowingExternalForceIsNamedAtForceAssemblyAndStateIsKept) {
  auto body = MakeMovingCube();
  const VecX x = body->x(), v = body->v();
  // Each force is finite (AddNodeForce accepts it); their sum is +inf.
  body->AddNodeForce(5, Vec3(0, 0, 1e308));
  body->AddNodeForce(5, Vec3(0, 0, 1e308));
  const std::string message = StepAndCatch(*body);
  ExpectMentions(message, {"body 'cube'", "external force on node 5", "stage: force assembly"});
  EXPECT_EQ(body->x(), x);
  EXPECT_EQ(body->v(), v);
  // The failed step's forces are dropped, so the body can go on from the kept state.
  body->BeginStep(kStep, kGravity);
  body->EndStep(kStep);
  EXPECT_TRUE(body->x().allFinite());
  EXPECT_LT((body->x() - x).cwiseAbs().maxCoeff(), 0.05);
}

TEST(DeformableBodyGuardTest, NonFiniteElasticForceNamesAnElementOfTheBadNode) {
  auto body = MakeMovingCube(kInf);
  VecX x = body->x();
  x[3 * 13 + 2] = 1e308;  // finite, but the deformation gradient of its tets overflows
  body->set_x(x);
  const VecX v = body->v();
  const std::string message = StepAndCatch(*body);
  ExpectMentions(message, {"body 'cube'", "elastic force of element", "stage: force assembly"});
  const int element = NumberAfter(message, "element ");
  ASSERT_GE(element, 0) << message;
  ASSERT_LT(element, body->model().num_elements());
  const int* nodes = body->model().element_nodes(element);
  EXPECT_NE(std::find(nodes, nodes + 4, 13), nodes + 4) << message;
  EXPECT_EQ(body->x(), x);
  EXPECT_EQ(body->v(), v);
}

// The largest free-node speed of the unconstrained velocity after one step with a 1e6 N push on
// node 5, on a body whose guard is off.
double PushedSpeed() {
  auto body = MakeMovingCube(kInf);
  body->AddNodeForce(5, Vec3(1e6, 0, 0));
  body->BeginStep(kStep, kGravity);
  double fastest = 0.0;
  for (int i = 0; i < body->num_nodes(); ++i)
    fastest = std::max(fastest, body->v_star().segment<3>(3 * i).norm());
  return fastest;
}

TEST(DeformableBodyGuardTest, ExplodingUnconstrainedVelocityTripsExactlyAboveMaxSpeed) {
  const double speed = PushedSpeed();
  ASSERT_GT(speed, 10.0);
  // Just above the limit: the step runs.
  auto calm = MakeMovingCube(1.01 * speed);
  calm->AddNodeForce(5, Vec3(1e6, 0, 0));
  EXPECT_NO_THROW(calm->BeginStep(kStep, kGravity));
  // Just below: the step stops after the solve and names the fastest node.
  auto body = MakeMovingCube(0.99 * speed);
  const VecX x = body->x(), v = body->v();
  body->AddNodeForce(5, Vec3(1e6, 0, 0));
  const std::string message = StepAndCatch(*body);
  ExpectMentions(message, {"body 'cube'", "above max_speed", "stage: unconstrained solve"});
  const int node = NumberAfter(message, "node ");
  ASSERT_GE(node, 0) << message;
  EXPECT_NEAR(body->v_star().segment<3>(3 * node).norm(), speed, 1e-9 * speed) << message;
  EXPECT_EQ(body->x(), x);
  EXPECT_EQ(body->v(), v);
}

TEST(DeformableBodyGuardTest, NanVelocityFromTheConstraintStageIsCaughtAtEndStep) {
  auto body = MakeMovingCube();
  const VecX x = body->x(), v = body->v();
  body->BeginStep(kStep, kGravity);
  body->mutable_v()[3 * 9 + 1] = std::numeric_limits<double>::quiet_NaN();
  try {
    body->EndStep(kStep);
    FAIL() << "EndStep accepted a NaN velocity";
  } catch (const SimulationError& e) {
    ExpectMentions(e.what(), {"body 'cube'", "non-finite velocity at node 9", "stage: end of step",
                              "state kept at step start"});
  }
  EXPECT_EQ(body->x(), x);
  EXPECT_EQ(body->v(), v);
}

TEST(DeformableBodyGuardTest, ExplodingConstrainedVelocityIsCaughtAtEndStep) {
  auto body = MakeMovingCube(100.0);
  const VecX x = body->x(), v = body->v();
  body->BeginStep(kStep, kGravity);
  body->mutable_v().segment<3>(3 * 20) = Vec3(0, 300, 0);  // as if a constraint went wild
  try {
    body->EndStep(kStep);
    FAIL() << "EndStep accepted 300 m/s with max_speed 100 m/s";
  } catch (const SimulationError& e) {
    ExpectMentions(e.what(), {"node 20 moves at 300 m/s", "max_speed = 100", "stage: end of step"});
  }
  EXPECT_EQ(body->x(), x);
  EXPECT_EQ(body->v(), v);
}

TEST(DeformableBodyGuardTest, KinematicNodesMayMoveFasterThanMaxSpeed) {
  // Every node kinematic, teleported 20 m in one 10 ms step (2000 m/s > max_speed 1000 m/s): the
  // motion is prescribed, not an explosion, so no guard trips.
  auto body = MakeMovingCube();
  for (int i = 0; i < body->num_nodes(); ++i)
    body->SetKinematicTarget(i, body->node_position(i) + Vec3(20, 0, 0));
  const VecX x = body->x();
  body->BeginStep(kStep, kGravity);
  body->EndStep(kStep);
  EXPECT_NEAR((body->x() - x).segment<3>(0).x(), 20.0, 1e-9);
  EXPECT_NEAR(body->v().segment<3>(0).x(), 2000.0, 1e-6);
}

}  // namespace
}  // namespace taut
