#include "plugin/implicit_system.h"

#include <algorithm>

namespace taut {

void ImplicitSystem::Build(const ElementModel& model, const std::vector<NodeKind>& kinds) {
  const int num_dofs = 3 * model.num_nodes();
  dof_to_free_.assign(num_dofs, -1);
  free_to_dof_.clear();
  for (int i = 0; i < model.num_nodes(); ++i)
    if (kinds[i] == NodeKind::kFree)
      for (int k = 0; k < 3; ++k) {
        dof_to_free_[3 * i + k] = static_cast<int>(free_to_dof_.size());
        free_to_dof_.push_back(3 * i + k);
      }
  const int n = num_free_dofs();
  // Pattern: every element couples all DOFs of its free nodes, plus the diagonal.
  const int k = model.nodes_per_element();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(model.num_elements()) * k * k * 9 + n);
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, 0.0);
  for (int e = 0; e < model.num_elements(); ++e) {
    const int* nodes = model.element_nodes(e);
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            const int row = dof_to_free_[3 * nodes[a] + r];
            const int col = dof_to_free_[3 * nodes[b] + c];
            if (row >= 0 && col >= 0) triplets.emplace_back(row, col, 0.0);
          }
  }
  A_.resize(n, n);
  A_.setFromTriplets(triplets.begin(), triplets.end());
  A_.makeCompressed();
  // Value index of (row, col) by binary search in the column.
  auto index_of = [this](int row, int col) {
    const int* begin = A_.innerIndexPtr() + A_.outerIndexPtr()[col];
    const int* end = A_.innerIndexPtr() + A_.outerIndexPtr()[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    TAUT_ASSERT(it != end && *it == row);
    return static_cast<int>(it - A_.innerIndexPtr());
  };
  diagonal_.resize(n);
  for (int i = 0; i < n; ++i) diagonal_[i] = index_of(i, i);
  element_map_.assign(static_cast<size_t>(model.num_elements()) * k * k * 9, -1);
  nodes_per_element_ = k;
  int* map = element_map_.data();
  for (int e = 0; e < model.num_elements(); ++e) {
    const int* nodes = model.element_nodes(e);
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b, map += 9)
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            const int row = dof_to_free_[3 * nodes[a] + r];
            const int col = dof_to_free_[3 * nodes[b] + c];
            map[3 * c + r] = (row >= 0 && col >= 0) ? index_of(row, col) : -1;
          }
  }
  // Backend by size (see the class comment); the other one is emptied to free its memory.
  use_cholmod_ = requested_solver_ == LinearSolverKind::kCholmod ||
                 (requested_solver_ == LinearSolverKind::kAuto && IsCholmodAvailable() &&
                  n >= kCholmodMinFreeDofs);
  ldlt_ = SparseLdlt();
  cholmod_ = CholmodCholesky();
  if (n > 0 && use_cholmod_) cholmod_.Analyze(A_);
  if (n > 0 && !use_cholmod_) ldlt_.Analyze(A_);
  rhs_free_.resize(n);
  product_free_.resize(n);
  for (VecX* v : {&cg_r_, &cg_z_, &cg_p_, &cg_ap_, &cg_x_}) v->resize(n);
  newton_analyzed_ = false;
  factor_current_ = false;
  exact_solves_ = false;
}

void ImplicitSystem::Assemble(const ElementModel& model, const VecX& mass, double c_M, double c_K) {
  double* values = A_.valuePtr();
  std::fill(values, values + A_.nonZeros(), 0.0);
  for (int i = 0; i < num_free_dofs(); ++i) values[diagonal_[i]] += c_M * mass[free_to_dof_[i] / 3];
  model.AddScaledStiffness(c_K, element_map_, values);
  factor_current_ = false;
}

bool ImplicitSystem::FactorWith(const Eigen::SparseMatrix<double>& M, SparseLdlt& ldlt,
                                CholmodCholesky& cholmod) const {
  return use_cholmod_ ? cholmod.Factorize(M)
                      : ldlt.Factorize(M, loop_runner_) && ldlt.num_negative_pivots() == 0;
}

void ImplicitSystem::SolveWith(const SparseLdlt& ldlt, const CholmodCholesky& cholmod,
                               Eigen::Ref<VecX> rhs) const {
  const int n = num_free_dofs();
  for (int i = 0; i < n; ++i) rhs_free_[i] = rhs[free_to_dof_[i]];
  rhs.setZero();
  if (n == 0) return;
  if (use_cholmod_)
    cholmod.Solve(rhs_free_);
  else
    ldlt.Solve(rhs_free_);
  for (int i = 0; i < n; ++i) rhs[free_to_dof_[i]] = rhs_free_[i];
}

void ImplicitSystem::MultiplyWith(const Eigen::SparseMatrix<double>& M, const VecX& v,
                                  VecX& out) const {
  const int n = num_free_dofs();
  for (int i = 0; i < n; ++i) rhs_free_[i] = v[free_to_dof_[i]];
  product_free_.noalias() = M * rhs_free_;
  out.setZero(v.size());
  for (int i = 0; i < n; ++i) out[free_to_dof_[i]] = product_free_[i];
}

void ImplicitSystem::Factor(const std::string& body) {
  factor_current_ = false;
  if (num_free_dofs() == 0) return;
  if (!FactorWith(A_, ldlt_, cholmod_))
    throw SimulationError(internal::Concat("body '", body,
                                           "': system matrix A = M + hD + h^2 K is not positive "
                                           "definite (stage: factorization)"));
  factor_current_ = true;
}

int ImplicitSystem::SolveStep(Eigen::Ref<VecX> rhs, const std::string& body,
                              const FactorReuseSettings& reuse) {
  const double cost = CalcRefactorCost(ldlt_);
  const bool try_kept = reuse.enabled && !use_cholmod_ && !exact_solves_ && ldlt_.factorized() &&
                        cost >= reuse.min_refactor_cost;
  exact_solves_ = false;
  if (try_kept) {
    const int n = num_free_dofs();
    for (int i = 0; i < n; ++i) cg_x_[i] = rhs[free_to_dof_[i]];
    ldlt_.MakeSinglePrecisionCopy();  // once per factor: the preconditioner's solves read fl32(L)
    const int iterations = SolveByKeptFactor(cg_x_, reuse.pcg_tolerance, static_cast<int>(cost));
    if (iterations >= 0) {
      rhs.setZero();
      for (int i = 0; i < n; ++i) rhs[free_to_dof_[i]] = cg_x_[i];
      return iterations;
    }
    // Out of budget: this step factors (below); the next reuses that fresh factor.
  }
  Factor(body);
  Solve(rhs);
  return 0;
}

int ImplicitSystem::SolveByKeptFactor(VecX& b_then_x, double tolerance, int max_iterations) const {
  // Preconditioned CG (Saad, Iterative Methods, Alg. 9.1) with P = the kept L D L^T of an earlier
  // A (its single-precision copy where one is kept), from x_0 = P^-1 b.
  cg_r_ = b_then_x;  // r = b
  const double threshold = tolerance * b_then_x.norm();
  if (threshold == 0.0) return 0;  // b = 0: x = 0
  ldlt_.Solve(b_then_x);  // x_0 = P^-1 b in double: exact where A has not changed (at rest)
  int applications = 1;
  cg_ap_.noalias() = A_ * b_then_x;
  cg_r_ -= cg_ap_;
  double rz_old = 0.0;
  while (cg_r_.norm() > threshold) {
    if (applications >= max_iterations) return -1;
    cg_z_ = cg_r_;
    ldlt_.SolveSinglePrecision(cg_z_);  // z = P^-1 r
    ++applications;
    const double rz = cg_r_.dot(cg_z_);
    if (applications == 2)
      cg_p_ = cg_z_;
    else
      cg_p_ = cg_z_ + (rz / rz_old) * cg_p_;
    rz_old = rz;
    cg_ap_.noalias() = A_ * cg_p_;
    const double alpha = rz / cg_p_.dot(cg_ap_);
    b_then_x += alpha * cg_p_;
    cg_r_ -= alpha * cg_ap_;
  }
  return applications;
}

void ImplicitSystem::EnsureCurrentFactor(const std::string& body) {
  exact_solves_ = true;
  if (!factor_current_) Factor(body);
}

double ImplicitSystem::CalcRefactorCost(const SparseLdlt& factor) const {
  if (use_cholmod_ || !factor.factorized() || num_free_dofs() == 0) return 0.0;
  const double iteration = 4.0 * factor.nonzeros_in_L() + 2.0 * A_.nonZeros();
  return factor.CalcFactorWork() / iteration;
}

void ImplicitSystem::Solve(Eigen::Ref<VecX> rhs) const {
  TAUT_ASSERT(factor_current_ || num_free_dofs() == 0);
  SolveWith(ldlt_, cholmod_, rhs);
}

void ImplicitSystem::SolveApproximately(Eigen::Ref<VecX> rhs, const std::string& body) {
  const bool kept = !use_cholmod_ && ldlt_.factorized();  // CHOLMOD's factor is never kept
  if (!factor_current_ && !kept) Factor(body);
  SolveWith(ldlt_, cholmod_, rhs);
}

void ImplicitSystem::SolveColumns(Eigen::Ref<MatX> rhs) const {
  TAUT_ASSERT(factor_current_ || num_free_dofs() == 0);
  SolveColumnsWith(ldlt_, cholmod_, rhs);
}

void ImplicitSystem::SolveColumnsWith(const SparseLdlt& ldlt, const CholmodCholesky& cholmod,
                                      Eigen::Ref<MatX> rhs) const {
  const int n = num_free_dofs();
  if (columns_free_.rows() != n || columns_free_.cols() < rhs.cols())
    columns_free_.resize(n, std::max<Eigen::Index>(rhs.cols(), columns_free_.cols()));
  auto cols = columns_free_.leftCols(rhs.cols());
  for (int i = 0; i < n; ++i) cols.row(i) = rhs.row(free_to_dof_[i]);
  rhs.setZero();
  if (n == 0) return;
  if (use_cholmod_)
    cholmod.SolveColumns(cols);
  else
    ldlt.SolveColumns(cols);
  for (int i = 0; i < n; ++i) rhs.row(free_to_dof_[i]) = cols.row(i);
}

bool ImplicitSystem::HalfSolvesPay(int num_rows) const {
  return supports_half_solve() &&
         static_cast<double>(num_rows) * num_free_dofs() < 4.0 * ldlt_.nonzeros_in_L();
}

void ImplicitSystem::HalfSolveColumns(const SparseColumns& rhs, MatX& z) const {
  TAUT_DEMAND(supports_half_solve(), "ImplicitSystem: half solves need the SparseLdlt backend");
  const int n = num_free_dofs();
  z.resize(n, rhs.cols());
  if (n == 0) return;
  TAUT_ASSERT(factor_current_);
  sparse_free_.Clear();
  for (int c = 0; c < rhs.cols(); ++c) {
    for (int e = rhs.start[c]; e < rhs.start[c + 1]; ++e) {
      TAUT_DEMAND(rhs.index[e] >= 0 && rhs.index[e] < static_cast<int>(dof_to_free_.size()),
                  "ImplicitSystem: half solve entry at DOF ", rhs.index[e], " of ",
                  dof_to_free_.size());
      const int free = dof_to_free_[rhs.index[e]];
      if (free >= 0) sparse_free_.Add(free, rhs.value[e]);
    }
    sparse_free_.EndColumn();
  }
  ldlt_.HalfSolveColumns(sparse_free_, z);
}

void ImplicitSystem::CompleteHalfSolve(const VecX& z, Eigen::Ref<VecX> out) const {
  TAUT_DEMAND(supports_half_solve(), "ImplicitSystem: half solves need the SparseLdlt backend");
  const int n = num_free_dofs();
  out.setZero();
  if (n == 0) return;
  TAUT_ASSERT(factor_current_);
  rhs_free_ = z;
  ldlt_.CompleteHalfSolve(rhs_free_);
  for (int i = 0; i < n; ++i) out[free_to_dof_[i]] = rhs_free_[i];
}

void ImplicitSystem::Multiply(const VecX& v, VecX& out) const { MultiplyWith(A_, v, out); }

void ImplicitSystem::ResetNewtonMatrix() {
  if (!newton_analyzed_) {
    H_ = A_;
    newton_ldlt_ = SparseLdlt();
    newton_cholmod_ = CholmodCholesky();
    if (num_free_dofs() > 0 && use_cholmod_) newton_cholmod_.Analyze(H_);
    if (num_free_dofs() > 0 && !use_cholmod_) newton_ldlt_.Analyze(H_);
    newton_analyzed_ = true;
  }
  std::copy(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), H_.valuePtr());
}

int ImplicitSystem::FindBlockRow(int a, int col) const {
  const int row = dof_to_free_[3 * a];
  const int* begin = A_.innerIndexPtr() + A_.outerIndexPtr()[col];
  const int* end = A_.innerIndexPtr() + A_.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  return (it != end && *it == row) ? static_cast<int>(it - A_.innerIndexPtr()) : -1;
}

bool ImplicitSystem::IsInPattern(int a, int b) const {
  if (dof_to_free_[3 * a] < 0 || dof_to_free_[3 * b] < 0) return true;
  return FindBlockRow(a, dof_to_free_[3 * b]) >= 0;
}

void ImplicitSystem::AddNewtonBlock(int a, int b, const Mat3& block) {
  if (dof_to_free_[3 * a] < 0 || dof_to_free_[3 * b] < 0) return;
  double* values = H_.valuePtr();
  // A node's three DOFs are free together and the pattern couples whole nodes, so the three
  // columns of node b have the same rows: node a's rows start at the same offset in each.
  const int col = dof_to_free_[3 * b];
  const int offset = FindBlockRow(a, col) - A_.outerIndexPtr()[col];
  TAUT_ASSERT(offset >= 0);
  for (int c = 0; c < 3; ++c) {
    const int start = A_.outerIndexPtr()[col + c] + offset;
    for (int r = 0; r < 3; ++r) values[start + r] += block(r, c);
  }
}

void ImplicitSystem::AddNewtonElementBlock(int e, const Eigen::Ref<const MatX>& block) {
  const int k = nodes_per_element_;
  TAUT_ASSERT(block.rows() == 3 * k && block.cols() == 3 * k);
  double* values = H_.valuePtr();
  const int* map = element_map_.data() + static_cast<size_t>(9 * k * k) * e;
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b, map += 9)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
          if (map[3 * c + r] >= 0) values[map[3 * c + r]] += block(3 * a + r, 3 * b + c);
}

void ImplicitSystem::FactorNewtonMatrix(const std::string& body) {
  if (num_free_dofs() == 0) return;
  if (!FactorWith(H_, newton_ldlt_, newton_cholmod_))
    throw SimulationError(internal::Concat("body '", body,
                                           "': Newton matrix A + sum rho J^T J is not positive "
                                           "definite (stage: primal constraint solve)"));
}

void ImplicitSystem::SolveNewton(Eigen::Ref<VecX> rhs) const {
  SolveWith(newton_ldlt_, newton_cholmod_, rhs);
}

void ImplicitSystem::SolveNewtonColumns(Eigen::Ref<MatX> rhs) const {
  SolveColumnsWith(newton_ldlt_, newton_cholmod_, rhs);
}

void ImplicitSystem::MultiplyNewton(const VecX& v, VecX& out) const { MultiplyWith(H_, v, out); }

bool ImplicitSystem::HasNewtonFactor() const {
  return newton_analyzed_ && num_free_dofs() > 0 && !use_cholmod_ && newton_ldlt_.factorized();
}

double ImplicitSystem::CalcNewtonRefactorCost() const {
  if (!HasNewtonFactor()) return 0.0;
  return CalcRefactorCost(newton_ldlt_);
}

ImplicitSystem::NewtonState ImplicitSystem::SaveNewtonState() const {
  NewtonState state;
  SaveNewtonState(state);
  return state;
}

void ImplicitSystem::SaveNewtonState(NewtonState& state) const {
  if (use_cholmod_) {
    state = NewtonState();
    return;
  }
  state.system_factor = ldlt_;
  state.exact_solves = exact_solves_;
  state.analyzed = newton_analyzed_;
  if (!newton_analyzed_) return;
  state.H = H_;
  state.factor = newton_ldlt_;
}

void ImplicitSystem::RestoreNewtonState(const NewtonState& state) {
  if (use_cholmod_) return;
  if (state.analyzed)
    TAUT_DEMAND(state.H.rows() == num_free_dofs() && state.H.nonZeros() == A_.nonZeros(),
                "Newton state of ", state.H.rows(), " free DOFs and ", state.H.nonZeros(),
                " entries does not fit this system (", num_free_dofs(), " free DOFs, ",
                A_.nonZeros(), " entries)");
  const bool factor_fits = state.system_factor.analyzed() &&
                           state.system_factor.rows() == num_free_dofs() &&
                           state.system_factor.nonzeros_in_L() == ldlt_.nonzeros_in_L();
  TAUT_DEMAND(factor_fits || !state.system_factor.analyzed(), "system factor of ",
              state.system_factor.rows(), " free DOFs does not fit this system (", num_free_dofs(),
              " free DOFs)");
  newton_analyzed_ = state.analyzed;
  // Without an analysis the saved H and factor are unused (SaveNewtonState may leave old ones).
  if (state.analyzed) {
    H_ = state.H;
    newton_ldlt_ = state.factor;
  } else {
    H_ = Eigen::SparseMatrix<double>();
    newton_ldlt_ = SparseLdlt();
  }
  if (factor_fits) ldlt_ = state.system_factor;
  factor_current_ = false;  // A is assembled again by the next step
  exact_solves_ = state.exact_solves;
}

}  // namespace taut
