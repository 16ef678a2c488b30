// The backend choice of ImplicitSystem in this build: CHOLMOD only with -DTAUT_WITH_CHOLMOD=ON
// (GPL-2+), else SparseLdlt for every body, and a clear InputError when CHOLMOD is asked for.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "plugin/cholmod_cholesky.h"
#include "plugin/implicit_system.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

// A soft cantilever of (nx x 2 x 2) cells, x = 0 face fixed, with its system assembled.
struct Beam {
  explicit Beam(int nx, int ny = 2, int nz = 2)
      : model(std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 0.2, 0.2), nx, ny, nz)),
              Material{2e4, 0.3, 1000.0}),
        kinds(model.num_nodes(), NodeKind::kFree) {
    for (int i = 0; i < model.num_nodes(); ++i)
      if (model.rest_positions()[3 * i] < 1e-9) kinds[i] = NodeKind::kFixed;
    VecX f = VecX::Zero(3 * model.num_nodes());
    model.UpdateRotationsAndAddForces(model.rest_positions(), f);
    model.CalcLumpedMass(1000.0, mass);
  }
  TetElementModel model;
  std::vector<NodeKind> kinds;
  VecX mass;
};

TEST(LinearSolverChoiceTest, BuildReportsWhetherItLinksCholmod) {
  EXPECT_EQ(IsCholmodAvailable(), TAUT_TEST_WITH_CHOLMOD != 0);
}

TEST(LinearSolverChoiceTest, AutoUsesCholmodForLargeBodiesOnlyWhenBuiltWithIt) {
  Beam beam(60);  // 1,620 free DOFs, above kCholmodMinFreeDofs
  ImplicitSystem system;
  system.Build(beam.model, beam.kinds);
  ASSERT_GE(system.num_free_dofs(), ImplicitSystem::kCholmodMinFreeDofs);
  EXPECT_EQ(system.uses_cholmod(), IsCholmodAvailable());
  // Either way the step's factor and solve work.
  system.Assemble(beam.model, beam.mass, 1.0, 1.0 / (240.0 * 240.0));
  system.Factor("beam");
  VecX rhs = VecX::Ones(3 * beam.model.num_nodes());
  system.Solve(rhs);
  EXPECT_TRUE(rhs.allFinite());
  EXPECT_GT(rhs.norm(), 0.0);
}

TEST(LinearSolverChoiceTest, ExplicitCholmodWithoutItThrowsInputErrorSayingHowToGetIt) {
  if (IsCholmodAvailable()) GTEST_SKIP() << "this build links CHOLMOD";
  Beam beam(3);
  ImplicitSystem system;
  system.set_linear_solver(LinearSolverKind::kCholmod);
  try {
    system.Build(beam.model, beam.kinds);
    FAIL() << "kCholmod in a build without CHOLMOD did not throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("TAUT_WITH_CHOLMOD=ON"), std::string::npos) << e.what();
  }
  CholmodCholesky chol;
  EXPECT_THROW(chol.Analyze(system.matrix()), InputError);
  EXPECT_EQ(chol.num_supernodes(), 0);
}

}  // namespace
}  // namespace taut
