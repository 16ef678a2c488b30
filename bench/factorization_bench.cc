// Sparse factorization backends on real implicit-step matrices A = M + h^2 K (co-rotated K of a
// twisted body, free DOFs only, h = 1/240 s): the tet beams of tet_scaling_bench.cc (1 x 0.2 x
// 0.2 m, E = 200 kPa, x = 0 end fixed), free hex balls of armadillo size (E = 500 kPa) and, when
// data/armadillo.off is present (scripts/fetch_armadillo.sh), the armadillo scene's 368-hex
// lattice. Backends, each its own benchmark BM_Factorization/<op>/<case>/<backend> (manual time,
// median of the repetitions in the Time column):
//   ldlt        SparseLdlt (taut's LDL^T, its ordering chosen: AMD, or nested dissection for large
//               bodies where it fills less): the default build's backend
//   ldlt_amd    SparseLdlt with AMD forced (the ordering before nested dissection, for the ratio)
//   ldlt_2threads  SparseLdlt factoring on two threads where its supernodal factor splits (the
//               same factor bit for bit; the ratio to ldlt is the 2-core speed-up of Factorize)
//   eigen_llt   Eigen's SimplicialLLT (AMD ordering)
//   cholmod     CHOLMOD's supernodal LL^T (only in builds with -DTAUT_WITH_CHOLMOD=ON, GPL-2+)
// op: factor_solve (numeric factorization + one solve, what every step does) or solve64 (64
// right-hand sides, the A^-1 J^T columns). Counters: dofs, elements, nnz_L (entries of L),
// rel_diff, the relative difference of the solution to ldlt's, and (SparseLdlt) nested_dissection,
// 1 when its ordering is nested dissection, factor_work, its multiply-adds per factorization, and
// split_share, the share of the supernodal factor's work in the two groups that ldlt_2threads
// factors in parallel (0: no split).
//   taut_bench --benchmark_filter=BM_Factorization
#include <benchmark/benchmark.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bullet_bridge/island_thread_pool.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/cholmod_cholesky.h"
#include "plugin/hex_element_model.h"
#include "plugin/hex_shapes.h"
#include "plugin/hex_voxelizer.h"
#include "plugin/implicit_system.h"
#include "plugin/off_reader.h"
#include "plugin/sparse_ldlt.h"
#include "plugin/surface_mesh.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

using SparseMatrix = SparseLdlt::SparseMatrix;

// A body shape: a tet beam of (n0 x n1 x n2) box cells, a hex ball n0 cells across, or (armadillo)
// the armadillo scene's lattice.
struct CaseSpec {
  bool hex_ball;
  int n0, n1, n2;
  bool armadillo = false;
  bool operator<(const CaseSpec& o) const {
    return std::tie(hex_ball, n0, n1, n2, armadillo) <
           std::tie(o.hex_ball, o.n0, o.n1, o.n2, o.armadillo);
  }
};

// The armadillo scan as the armadillo scene voxelizes it: 2 m tall, cells of 0.1145 m (368 hexes).
std::string ArmadilloPath() {
  return (std::filesystem::path(__FILE__).parent_path().parent_path() / "data" / "armadillo.off")
      .string();
}
HexLattice MakeArmadilloLattice() {
  SurfaceMesh scan = ReadOffSurface(ArmadilloPath());
  const Eigen::AlignedBox3d bounds = CalcSurfaceBounds(scan);
  const double scale = 2.0 / bounds.sizes().y();
  for (Vec3& v : scan.vertices) {
    const Vec3 u = (v - bounds.min()) * scale;
    v = Vec3(u.x(), -u.z(), u.y());
  }
  return VoxelizeSurface(scan, 0.1145);
}

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
  if (spec.hex_ball || spec.armadillo) {
    density = 500.0;
    auto lattice = std::make_shared<HexLattice>(
        spec.armadillo ? MakeArmadilloLattice() : MakeSphereHexLattice(1.0, 2.0 / spec.n0));
    model = std::make_unique<HexElementModel>(lattice, Material{500e3, 0.3, density});
  } else {
    density = 1000.0;
    auto mesh =
        std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1.0, 0.2, 0.2), spec.n0, spec.n1, spec.n2));
    model = std::make_unique<TetElementModel>(mesh, Material{200e3, 0.3, density});
  }
  kinds.assign(model->num_nodes(), NodeKind::kFree);
  for (int i = 0; i < model->num_nodes(); ++i)
    if (!spec.hex_ball && !spec.armadillo && model->rest_positions()[3 * i] < 1e-9)
      kinds[i] = NodeKind::kFixed;
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

// Eigen's SimplicialLLT (AMD) behind the Analyze / Factorize / Solve / SolveColumns interface.
class EigenLlt {
 public:
  void Analyze(const SparseMatrix& A) { llt_.analyzePattern(A); }
  bool Factorize(const SparseMatrix& A) {
    llt_.factorize(A);
    return llt_.info() == Eigen::Success;
  }
  void Solve(VecX& x) const { x = llt_.solve(x); }
  void SolveColumns(MatX& X) const { X = llt_.solve(X); }
  double nonzeros_in_L() const {
    return static_cast<double>(llt_.matrixL().nestedExpression().nonZeros());
  }

 private:
  Eigen::SimplicialLLT<SparseMatrix, Eigen::Upper> llt_;
};

// SparseLdlt with the AMD ordering forced.
class AmdLdlt : public SparseLdlt {
 public:
  void Analyze(const SparseMatrix& A) { SparseLdlt::Analyze(A, Kernel::kAuto, Ordering::kAmd); }
};

// SparseLdlt factoring on two threads (SupernodalCholesky's two-way split).
class TwoThreadLdlt : public SparseLdlt {
 public:
  bool Factorize(const SparseMatrix& A) { return SparseLdlt::Factorize(A, &pool_); }

 private:
  IslandThreadPool pool_{2};
};

// 1 when the backend ordered by nested dissection (SparseLdlt), else 0.
double UsesNestedDissection(const SparseLdlt& s) {
  return s.ordering() == SparseLdlt::Ordering::kNestedDissection ? 1.0 : 0.0;
}
double UsesNestedDissection(const CholmodCholesky&) { return 0.0; }
double UsesNestedDissection(const EigenLlt&) { return 0.0; }

// Multiply-adds of one factorization (SparseLdlt::CalcFactorWork; 0 for the other backends).
double FactorWork(const SparseLdlt& s) { return s.CalcFactorWork(); }
// Share of the supernodal factor's estimated work in its two subtree groups (0 without a split).
double SplitShare(const SparseLdlt& s) {
  if (!s.supernodal() || !s.supernodal_factor().has_two_way_split()) return 0.0;
  const std::array<double, 3>& w = s.supernodal_factor().split_work();
  return (w[0] + w[1]) / (w[0] + w[1] + w[2]);
}
double SplitShare(const CholmodCholesky&) { return 0.0; }
double SplitShare(const EigenLlt&) { return 0.0; }
double FactorWork(const CholmodCholesky&) { return 0.0; }
double FactorWork(const EigenLlt&) { return 0.0; }

// Entries of L of each backend (CHOLMOD: stored supernodal entries).
double EntriesOfL(const SparseLdlt& s) { return s.nonzeros_in_L(); }
double EntriesOfL(const CholmodCholesky& s) { return s.stored_entries_in_L(); }
double EntriesOfL(const EigenLlt& s) { return s.nonzeros_in_L(); }

// SparseLdlt's solution of the case (the reference of rel_diff), computed once per case and op.
const MatX& ReferenceSolution(const CaseSpec& spec, const FemCase& c, Op op) {
  static std::map<std::pair<CaseSpec, int>, MatX> refs;
  auto key = std::make_pair(spec, static_cast<int>(op));
  auto found = refs.find(key);
  if (found != refs.end()) return found->second;
  SparseLdlt ldlt;
  ldlt.Analyze(c.A);
  VecX x;
  MatX X;
  if (op == Op::kSolve64) ldlt.Factorize(c.A);
  RunOp(ldlt, c, op, x, X);
  return refs[key] = op == Op::kFactorSolve ? MatX(x) : X;
}

// Times one backend (analysis outside the loop).
template <class Solver>
void RunBackend(benchmark::State& state, Solver& solver, Op op, const CaseSpec& spec) {
  const FemCase& c = GetCase(spec);
  const MatX& ref = ReferenceSolution(spec, c, op);
  solver.Analyze(c.A);
  if (op == Op::kSolve64 && !solver.Factorize(c.A)) throw SimulationError("factorization failed");
  VecX x;
  MatX X;
  for (auto _ : state) {
    const double t0 = Now();
    RunOp(solver, c, op, x, X);
    state.SetIterationTime(Now() - t0);
  }
  const double diff =
      op == Op::kFactorSolve ? (x - ref.col(0)).norm() / ref.norm() : (X - ref).norm() / ref.norm();
  state.counters["dofs"] = static_cast<double>(c.A.rows());
  state.counters["elements"] = c.elements;
  state.counters["nnz_L"] = EntriesOfL(solver);
  state.counters["rel_diff"] = diff;
  state.counters["nested_dissection"] = UsesNestedDissection(solver);
  state.counters["factor_work"] = FactorWork(solver);
  state.counters["split_share"] = SplitShare(solver);
}

// The backends.
enum class Backend { kLdlt, kLdlt2Threads, kLdltAmd, kEigenLlt, kCholmod };

void BM_Factor(benchmark::State& state, Op op, CaseSpec spec, Backend backend) {
  switch (backend) {
    case Backend::kLdlt: {
      SparseLdlt s;
      RunBackend(state, s, op, spec);
      break;
    }
    case Backend::kLdlt2Threads: {
      TwoThreadLdlt s;
      RunBackend(state, s, op, spec);
      break;
    }
    case Backend::kLdltAmd: {
      AmdLdlt s;
      RunBackend(state, s, op, spec);
      break;
    }
    case Backend::kEigenLlt: {
      EigenLlt s;
      RunBackend(state, s, op, spec);
      break;
    }
    case Backend::kCholmod: {
      CholmodCholesky s;
      RunBackend(state, s, op, spec);
      break;
    }
  }
}

// Registers both operations on tet beams (cells, aspect ~5) of ~200, 300, 500, 1k, 2k, 5k, 20k,
// 25k and 100k tets, hex balls of 4, 5, 7, 9 and 12 cells across (9 is the armadillo's 368-hex
// size) and the armadillo itself (when its scan is present), for every backend of this build.
const bool kRegistered = [] {
  struct NamedCase {
    const char* name;
    CaseSpec spec;
  };
  std::vector<NamedCase> cases = {
      {"tet_200", {false, 8, 2, 2}},     {"tet_300", {false, 12, 2, 2}},
      {"tet_500", {false, 14, 2, 3}},    {"tet_1k", {false, 19, 3, 3}},
      {"tet_2k", {false, 23, 4, 4}},     {"tet_5k", {false, 33, 5, 5}},
      {"tet_20k", {false, 52, 8, 8}},    {"tet_25k", {false, 65, 8, 8}},
      {"tet_100k", {false, 76, 15, 15}}, {"hex_ball_4", {true, 4, 0, 0}},
      {"hex_ball_5", {true, 5, 0, 0}},   {"hex_ball_7", {true, 7, 0, 0}},
      {"hex_ball_9", {true, 9, 0, 0}},   {"hex_ball_12", {true, 12, 0, 0}},
  };
  if (std::filesystem::exists(ArmadilloPath()))
    cases.push_back({"armadillo", {false, 0, 0, 0, true}});
  std::vector<std::pair<Backend, const char*>> backends = {
      {Backend::kLdlt, "ldlt"},
      {Backend::kLdlt2Threads, "ldlt_2threads"},
      {Backend::kLdltAmd, "ldlt_amd"},
      {Backend::kEigenLlt, "eigen_llt"}};
  if (IsCholmodAvailable()) backends.push_back({Backend::kCholmod, "cholmod"});
  for (const auto& [op, op_name] :
       {std::pair{Op::kFactorSolve, "factor_solve"}, std::pair{Op::kSolve64, "solve64"}})
    for (const NamedCase& c : cases)
      for (const auto& [backend, backend_name] : backends) {
        // 100k tets: the simplicial backends take ~20 s per factorization; SparseLdlt only.
        if (std::string(c.name) == "tet_100k" && backend == Backend::kEigenLlt) continue;
        // The solves are the same on two threads.
        if (op == Op::kSolve64 && backend == Backend::kLdlt2Threads) continue;
        benchmark::RegisterBenchmark(
            (std::string("BM_Factorization/") + op_name + "/" + c.name + "/" + backend_name)
                .c_str(),
            BM_Factor, op, c.spec, backend)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
      }
  return true;
}();

}  // namespace
}  // namespace taut
