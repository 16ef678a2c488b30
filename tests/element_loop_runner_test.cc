// Split element loops (plugin/element_loop_runner.h): a body stepped with its element loops on a
// runner ends bitwise where the one-thread body ends, whatever order the chunks run in.
#include "plugin/element_loop_runner.h"

#include <gtest/gtest.h>

#include "bullet_bridge/island_thread_pool.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/hex_element_model.h"
#include "plugin/hex_lattice.h"
#include "plugin/hex_shapes.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

// Runs the chunks on the calling thread, last to first, and counts them.
class ReversedRunner : public ElementLoopRunner {
 public:
  explicit ReversedRunner(int threads = 2) : threads_(threads) {}
  int num_loop_threads() const override { return threads_; }
  int chunks_run = 0;

 protected:
  void RunChunksErased(int num_chunks, ChunkCall call, void* chunk) override {
    for (int c = num_chunks - 1; c >= 0; --c) {
      call(chunk, c);
      ++chunks_run;
    }
  }

 private:
  int threads_;
};

std::unique_ptr<DeformableBody> MakeTetBeam() {
  DeformableBodySettings settings;
  settings.name = "beam";
  settings.material = Material{5e4, 0.3, 1000};
  settings.mass_damping = 0.5;
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 0.2, 0.2), 10, 2, 2));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  return body;
}

std::unique_ptr<DeformableBody> MakeHexBall() {
  DeformableBodySettings settings;
  settings.name = "ball";
  settings.material = Material{1e5, 0.3, 1000};
  auto lattice = std::make_shared<HexLattice>(MakeSphereHexLattice(1.0, 0.25));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<HexElementModel>(lattice, settings.material), settings);
  body->FixNodesWhere([](const Vec3& X) { return X.z() < -0.6; });
  return body;
}

// A tet block whose factor splits over two threads (SupernodalCholesky::has_two_way_split),
// refactored every step (no factor reuse).
std::unique_ptr<DeformableBody> MakeLargeTetBlock() {
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = Material{5e4, 0.3, 1000};
  settings.factor_reuse.enabled = false;
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 0.6, 0.5), 10, 6, 5));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  return body;
}

// Steps `body` (with `runner` on its loops) and `reference` (one thread) side by side.
void ExpectSameSteps(DeformableBody& body, DeformableBody& reference, ElementLoopRunner* runner) {
  body.set_element_loop_runner(runner);
  for (int step = 0; step < 20; ++step) {
    for (DeformableBody* b : {&body, &reference}) {
      b->BeginStep(1.0 / 240.0, Vec3(0.3, 0, -9.81));
      b->EndStep(1.0 / 240.0);
    }
    ASSERT_EQ(body.x(), reference.x()) << "step " << step;
    ASSERT_EQ(body.v(), reference.v()) << "step " << step;
  }
  EXPECT_NE(body.x(), body.model().rest_positions());  // it moved
}

TEST(ElementLoopRunnerTest, TetBodyOnReversedChunksIsBitwiseTheSerialBody) {
  auto body = MakeTetBeam(), reference = MakeTetBeam();
  ASSERT_GE(body->model().num_elements(), 64);  // enough elements to split
  ReversedRunner runner;
  ExpectSameSteps(*body, *reference, &runner);
  EXPECT_GT(runner.chunks_run, 0);  // the split loops ran
}

TEST(ElementLoopRunnerTest, HexBodyOnReversedChunksIsBitwiseTheSerialBody) {
  auto body = MakeHexBall(), reference = MakeHexBall();
  ASSERT_GE(body->model().num_elements(), 64);
  ReversedRunner runner;
  ExpectSameSteps(*body, *reference, &runner);
  EXPECT_GT(runner.chunks_run, 0);
}

TEST(ElementLoopRunnerTest, HexBodyAssembledByThreeRowOwnersIsBitwiseTheSerialBody) {
  // The stiffness assembly splits A's rows into one node range per thread; with three, two
  // boundaries cut the ball and their elements are computed by two parts each.
  auto body = MakeHexBall(), reference = MakeHexBall();
  ReversedRunner runner(3);
  ExpectSameSteps(*body, *reference, &runner);
  EXPECT_GT(runner.chunks_run, 0);
}

TEST(ElementLoopRunnerTest, TetBodyOnTwoThreadsIsBitwiseTheSerialBody) {
  auto body = MakeTetBeam(), reference = MakeTetBeam();
  IslandThreadPool pool(2);
  ExpectSameSteps(*body, *reference, &pool);
}

// The factorization splits too (two subtree groups, then the supernodes above): bitwise the
// serial body, with the groups run in either order.
TEST(ElementLoopRunnerTest, LargeBodyWithASplitFactorIsBitwiseTheSerialBody) {
  if (IsCholmodAvailable()) GTEST_SKIP() << "a CHOLMOD build factors this body with CHOLMOD";
  auto body = MakeLargeTetBlock(), reference = MakeLargeTetBlock();
  ReversedRunner runner;
  ExpectSameSteps(*body, *reference, &runner);
  const SparseLdlt& factor = body->system().sparse_ldlt();
  EXPECT_TRUE(factor.supernodal() && factor.supernodal_factor().has_two_way_split());
  auto pooled = MakeLargeTetBlock(), pooled_reference = MakeLargeTetBlock();
  IslandThreadPool pool(2);
  ExpectSameSteps(*pooled, *pooled_reference, &pool);
}

}  // namespace
}  // namespace taut
