// SparseLdlt vs CholmodCholesky on real implicit-step matrices A = M + h^2 K (co-rotated K of a
// twisted body, free DOFs only, h = 1/240 s): the tet beams of tet_scaling_bench.cc (1 x 0.2 x
// 0.2 m, E = 200 kPa, x = 0 end fixed) and free hex balls of armadillo size (E = 500 kPa).
// Each benchmark times CHOLMOD (manual time: Time column, cholmod_ms = median) and, in the same
// run, SparseLdlt on the same matrix (ldlt_ms: median of up to 5 runs within ~1 s), and reports
// speedup = ldlt_ms / cholmod_ms and the relative difference of the two solutions.
// ImplicitSystem::kCholmodMinFreeDofs is the crossover of BM_FactorSolve.
//   taut_bench --benchmark_filter=BM_Factorization
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "plugin/cholmod_cholesky.h"
#include "plugin/hex_element_model.h"
#include "plugin/hex_shapes.h"
#include "plugin/implicit_system.h"
#include "plugin/sparse_ldlt.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

using SparseMatrix = SparseLdlt::SparseMatrix;

// A body shape: a tet beam of (n0 x n1 x n2) box cells, or a hex ball n0 cells across.
struct CaseSpec {
  bool hex_ball;
  int n0, n1, n2;
  bool operator<(const CaseSpec& o) const {
    return std::tie(hex_ball, n0, n1, n2) < std::tie(o.hex_ball, o.n0, o.n1, o.n2);
  }
};

// The system matrix of one body and right-hand sides.
struct FemCase {
  SparseMatrix A;  // full symmetric CSC, free DOFs
  VecX b;          // random
  MatX B;          // (dofs x 64) random
  int elements = 0;
};

// Element model of the case (rest state) and its node kinds (beam: x = 0 face fixed).
std::unique_ptr<ElementModel> MakeModel(const CaseSpec& spec, std::vector<NodeKind>& kinds,
                                        double& density) {
  std::unique_ptr<ElementModel> model;
  if (spec.hex_ball) {
    density = 500.0;
    auto lattice = std::make_shared<HexLattice>(MakeSphereHexLattice(1.0, 2.0 / spec.n0));
    model = std::make_unique<HexElementModel>(lattice, Material{500e3, 0.3, density});
  } else {
    density = 1000.0;
    auto mesh =
        std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1.0, 0.2, 0.2), spec.n0, spec.n1, spec.n2));
    model = std::make_unique<TetElementModel>(mesh, Material{200e3, 0.3, density});
  }
  kinds.assign(model->num_nodes(), NodeKind::kFree);
  for (int i = 0; i < model->num_nodes(); ++i)
    if (!spec.hex_ball && model->rest_positions()[3 * i] < 1e-9) kinds[i] = NodeKind::kFixed;
  return model;
}

// Builds (once per spec) A at a twisted pose, so every element has its own rotation.
const FemCase& GetCase(const CaseSpec& spec) {
  static std::map<CaseSpec, FemCase> cases;
  auto found = cases.find(spec);
  if (found != cases.end()) return found->second;
  std::vector<NodeKind> kinds;
  double density = 0.0;
  std::unique_ptr<ElementModel> model = MakeModel(spec, kinds, density);
  // Twist about x by 0.8 rad per m of x.
  VecX x = model->rest_positions();
  for (int i = 0; i < model->num_nodes(); ++i) {
    const Vec3 X = x.segment<3>(3 * i);
    x.segment<3>(3 * i) = Eigen::AngleAxisd(0.8 * X.x(), Vec3::UnitX()) * X;
  }
  VecX f = VecX::Zero(x.size()), mass;
  model->UpdateRotationsAndAddForces(x, f);
  model->CalcLumpedMass(density, mass);
  ImplicitSystem system;
  system.set_linear_solver(LinearSolverKind::kSparseLdlt);
  system.Build(*model, kinds);
  const double h = 1.0 / 240.0;
  system.Assemble(*model, mass, 1.0, h * h);
  FemCase& out = cases[spec];
  out.A = system.matrix();
  out.elements = model->num_elements();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  out.b = VecX::NullaryExpr(out.A.rows(), [&] { return u(rng); });
  out.B = MatX::NullaryExpr(out.A.rows(), 64, [&] { return u(rng); });
  return out;
}

// Seconds since an arbitrary start.
double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Median of the values (copied).
double CalcMedian(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// What a benchmark times.
enum class Op { kFactorSolve, kSolve64 };

// One numeric factorization plus one solve (kFactorSolve) or a 64-column solve (kSolve64) of
// `solver` on the case; x / X receive the solution.
template <class Solver>
void RunOp(Solver& solver, const FemCase& c, Op op, VecX& x, MatX& X) {
  if (op == Op::kFactorSolve) {
    if (!solver.Factorize(c.A)) throw SimulationError("factorization failed");
    x = c.b;
    solver.Solve(x);
  } else {
    X = c.B;
    solver.SolveColumns(X);
  }
}

// Times CHOLMOD in the loop and SparseLdlt once per call; reports the ratio.
void BM_Factor(benchmark::State& state, Op op, CaseSpec spec) {
  const FemCase& c = GetCase(spec);
  SparseLdlt ldlt;
  ldlt.Analyze(c.A);
  CholmodCholesky cholmod;
  cholmod.Analyze(c.A);
  VecX x_ldlt, x_chol;
  MatX X_ldlt, X_chol;
  if (op == Op::kSolve64) {
    ldlt.Factorize(c.A);
    cholmod.Factorize(c.A);
  }
  std::vector<double> ldlt_s;
  for (double start = Now(); ldlt_s.size() < 5 && (ldlt_s.empty() || Now() - start < 1.0);) {
    const double t0 = Now();
    RunOp(ldlt, c, op, x_ldlt, X_ldlt);
    ldlt_s.push_back(Now() - t0);
  }
  std::vector<double> cholmod_s;
  for (auto _ : state) {
    const double t0 = Now();
    RunOp(cholmod, c, op, x_chol, X_chol);
    cholmod_s.push_back(Now() - t0);
    state.SetIterationTime(cholmod_s.back());
  }
  const double diff = op == Op::kFactorSolve ? (x_chol - x_ldlt).norm() / x_ldlt.norm()
                                             : (X_chol - X_ldlt).norm() / X_ldlt.norm();
  state.counters["dofs"] = static_cast<double>(c.A.rows());
  state.counters["elements"] = c.elements;
  state.counters["ldlt_ms"] = 1e3 * CalcMedian(ldlt_s);
  state.counters["cholmod_ms"] = 1e3 * CalcMedian(cholmod_s);
  state.counters["speedup"] = CalcMedian(ldlt_s) / CalcMedian(cholmod_s);
  state.counters["nnz_L_ldlt"] = ldlt.nonzeros_in_L();
  state.counters["stored_L_cholmod"] = cholmod.stored_entries_in_L();
  state.counters["supernodes"] = cholmod.num_supernodes();
  state.counters["rel_diff"] = diff;
}

// Registers both operations on tet beams (cells, aspect ~5) of ~200, 300, 500, 1k, 2k, 5k, 20k and
// 100k tets and hex balls of 4, 5, 7, 9 and 12 cells across (9 is the armadillo's 368-hex size).
const bool kRegistered = [] {
  struct NamedCase {
    const char* name;
    CaseSpec spec;
  };
  const NamedCase cases[] = {
      {"tet_200", {false, 8, 2, 2}},     {"tet_300", {false, 12, 2, 2}},
      {"tet_500", {false, 14, 2, 3}},    {"tet_1k", {false, 19, 3, 3}},
      {"tet_2k", {false, 23, 4, 4}},     {"tet_5k", {false, 33, 5, 5}},
      {"tet_20k", {false, 52, 8, 8}},    {"tet_100k", {false, 76, 15, 15}},
      {"hex_ball_4", {true, 4, 0, 0}},   {"hex_ball_5", {true, 5, 0, 0}},
      {"hex_ball_7", {true, 7, 0, 0}},   {"hex_ball_9", {true, 9, 0, 0}},
      {"hex_ball_12", {true, 12, 0, 0}},
  };
  for (const auto& [op, op_name] :
       {std::pair{Op::kFactorSolve, "factor_solve"}, std::pair{Op::kSolve64, "solve64"}})
    for (const NamedCase& c : cases)
      benchmark::RegisterBenchmark(
          (std::string("BM_Factorization/") + op_name + "/" + c.name).c_str(), BM_Factor, op,
          c.spec)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace taut
