#include "plugin/cholmod_cholesky.h"

#if TAUT_WITH_CHOLMOD
#include <cholmod.h>
#include <dlfcn.h>

#include <algorithm>
#include <cmath>

namespace taut {

bool IsCholmodAvailable() { return true; }

namespace internal {

// CHOLMOD's settings, factor and the solve workspace of one CholmodCholesky.
struct CholmodState {
  cholmod_common common;
  cholmod_factor* L = nullptr;
  std::vector<double> y;  // (n x kMaxBlockColumns) column-major Y = P B
  std::vector<double> e;  // (kMaxBlockColumns x L->maxesize) workspace of the supernodal solves

  // Default CHOLMOD settings except: always supernodal (the analysis would pick the simplicial
  // method for small flop counts); merge adjacent supernodes of up to 16 columns whatever their
  // zero fraction (default 4): fewer, larger BLAS calls, measured 10-20 % faster below 5k DOFs and
  // neutral above; stop at the first non-positive pivot; print nothing (failures are reported by
  // return value or exception).
  CholmodState() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.nrelax[0] = 16;
    common.nrelax[1] = 32;
    common.quick_return_if_not_posdef = 1;
    common.print = 0;
  }
  ~CholmodState() {
    cholmod_free_factor(&L, &common);
    cholmod_finish(&common);
  }
  CholmodState(const CholmodState&) = delete;
  CholmodState& operator=(const CholmodState&) = delete;
};

// Destroys the state through the complete type.
void CholmodStateDeleter::operator()(CholmodState* state) const { delete state; }

}  // namespace internal

namespace {

// A CHOLMOD header over an Eigen CSC matrix's arrays (no copy): square, upper triangle used.
cholmod_sparse ViewUpper(const CholmodCholesky::SparseMatrix& A) {
  cholmod_sparse view{};
  view.nrow = view.ncol = static_cast<size_t>(A.rows());
  view.nzmax = static_cast<size_t>(A.nonZeros());
  view.p = const_cast<int*>(A.outerIndexPtr());
  view.i = const_cast<int*>(A.innerIndexPtr());
  view.x = const_cast<double*>(A.valuePtr());
  view.stype = 1;
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;  // Eigen keeps row indices ascending within a column
  view.packed = 1;
  return view;
}

// A CHOLMOD header over a column-major (rows x cols) block with leading dimension ld.
cholmod_dense ViewDense(double* x, size_t rows, size_t cols, size_t ld) {
  cholmod_dense view{};
  view.nrow = rows;
  view.ncol = cols;
  view.nzmax = ld * cols;
  view.d = ld;
  view.x = x;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  return view;
}

// omp_get_max_active_levels / omp_set_max_active_levels of the OpenMP runtime CHOLMOD brought
// into the process (Debian's libcholmod links libgomp), or null when CHOLMOD runs without one.
// Looked up at run time so that taut itself neither compiles with OpenMP nor links a runtime.
struct OpenMpLevelsApi {
  int (*get)() = nullptr;
  void (*set)(int) = nullptr;
};

// The process's OpenMP runtime entry points, looked up once.
const OpenMpLevelsApi& FindOpenMpLevelsApi() {
  static const OpenMpLevelsApi api = [] {
    OpenMpLevelsApi found;
    found.get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
    found.set = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
    return found.get && found.set ? found : OpenMpLevelsApi{};
  }();
  return api;
}

// Runs CHOLMOD single-threaded while alive. CHOLMOD 5's supernodal factorization clears and
// assembles in OpenMP regions of a fixed 4 threads (CHOLMOD_OMP_NUM_THREADS); bodies are stepped
// on one thread and the BLAS is serial, so waking those threads only adds overhead (measured on 2
// cores: 84 -> 47 ms at 20k tets, 26 -> 14 ms for the 912-hex ball). max-active-levels = 0 makes
// every parallel region inactive; the previous value is restored. The setting is process-wide, so
// OpenMP code on other threads runs serially during a factorization too.
class ScopedSerialOpenMp {
 public:
  ScopedSerialOpenMp() : api_(FindOpenMpLevelsApi()) {
    if (api_.set == nullptr) return;
    saved_ = api_.get();
    api_.set(0);
  }
  ~ScopedSerialOpenMp() {
    if (api_.set != nullptr) api_.set(saved_);
  }
  ScopedSerialOpenMp(const ScopedSerialOpenMp&) = delete;
  ScopedSerialOpenMp& operator=(const ScopedSerialOpenMp&) = delete;

 private:
  const OpenMpLevelsApi& api_;
  int saved_ = 0;
};

// Throws SimulationError naming the stage when CHOLMOD reports an error (status < 0).
void DemandCholmodOk(const cholmod_common& common, const char* stage) {
  if (common.status >= CHOLMOD_OK) return;
  const char* what = common.status == CHOLMOD_OUT_OF_MEMORY ? "out of memory"
                     : common.status == CHOLMOD_TOO_LARGE   ? "problem too large for int indices"
                                                            : "internal error";
  throw SimulationError(internal::Concat("CholmodCholesky::", stage, ": CHOLMOD failed (", what,
                                         ", status ", common.status, ")"));
}

}  // namespace

CholmodCholesky::CholmodCholesky() = default;
CholmodCholesky::~CholmodCholesky() = default;
CholmodCholesky::CholmodCholesky(CholmodCholesky&&) noexcept = default;
CholmodCholesky& CholmodCholesky::operator=(CholmodCholesky&&) noexcept = default;

// Symbolic phase: validate, CHOLMOD analysis (ordering + supernodal symbolic), solve workspace.
void CholmodCholesky::Analyze(const SparseMatrix& pattern) {
  analyzed_ = false;
  factorized_ = false;
  failed_column_ = -1;
  state_.reset();
  TAUT_DEMAND(pattern.rows() == pattern.cols(),
              "CholmodCholesky::Analyze: matrix must be square, got ", pattern.rows(), "x",
              pattern.cols());
  TAUT_DEMAND(pattern.rows() > 0, "CholmodCholesky::Analyze: matrix is empty");
  TAUT_DEMAND(pattern.isCompressed(),
              "CholmodCholesky::Analyze: matrix must be compressed (call makeCompressed())");
  n_ = static_cast<int>(pattern.rows());
  a_outer_.assign(pattern.outerIndexPtr(), pattern.outerIndexPtr() + n_ + 1);
  a_inner_.assign(pattern.innerIndexPtr(), pattern.innerIndexPtr() + pattern.nonZeros());

  state_.reset(new internal::CholmodState);
  cholmod_common& common = state_->common;
  cholmod_sparse A = ViewUpper(pattern);
  state_->L = cholmod_analyze(&A, &common);
  DemandCholmodOk(common, "Analyze");
  TAUT_ASSERT(state_->L != nullptr && state_->L->is_super);
  const int* perm = static_cast<const int*>(state_->L->Perm);
  perm_.assign(perm, perm + n_);
  state_->y.assign(static_cast<size_t>(n_) * kMaxBlockColumns, 0.0);
  state_->e.assign(std::max<size_t>(1, kMaxBlockColumns * state_->L->maxesize), 0.0);
  analyzed_ = true;
}

// Numeric phase: finiteness check of the upper triangle, then CHOLMOD's supernodal LL^T.
bool CholmodCholesky::Factorize(const SparseMatrix& A) {
  TAUT_DEMAND(analyzed_, "CholmodCholesky::Factorize called before Analyze");
  TAUT_DEMAND(A.rows() == n_ && A.cols() == n_ && A.isCompressed() &&
                  A.nonZeros() == static_cast<Eigen::Index>(a_inner_.size()) &&
                  std::equal(a_outer_.begin(), a_outer_.end(), A.outerIndexPtr()),
              "CholmodCholesky::Factorize: matrix (", A.rows(), "x", A.cols(), ", ", A.nonZeros(),
              " nonzeros) does not have the analysed pattern (", n_, "x", n_, ", ", a_inner_.size(),
              " nonzeros)");
  TAUT_ASSERT(std::equal(a_inner_.begin(), a_inner_.end(), A.innerIndexPtr()));
  factorized_ = false;
  failed_column_ = -1;
  // LAPACK's dpotrf need not stop at a NaN pivot, so non-finite input is caught here.
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* values = A.valuePtr();
  for (int c = 0; c < n_; ++c)
    for (int p = outer[c]; p < outer[c + 1] && inner[p] <= c; ++p)
      if (!std::isfinite(values[p])) {
        failed_column_ = c;
        return false;
      }
  cholmod_common& common = state_->common;
  cholmod_sparse view = ViewUpper(A);
  {
    ScopedSerialOpenMp serial;
    cholmod_factorize(&view, state_->L, &common);
  }
  if (common.status == CHOLMOD_NOT_POSDEF) {
    failed_column_ = perm_[std::min<size_t>(state_->L->minor, n_ - 1)];
    return false;
  }
  DemandCholmodOk(common, "Factorize");
  factorized_ = true;
  return true;
}

// Checks that a factor exists and the right-hand side fits it.
void CholmodCholesky::DemandReadyToSolve(Eigen::Index size) const {
  TAUT_DEMAND(factorized_ && state_, "CholmodCholesky: solve without a successful Factorize");
  TAUT_DEMAND(size == n_, "CholmodCholesky: right-hand side has ", size, " rows, the matrix has ",
              n_);
}

// One right-hand side.
void CholmodCholesky::Solve(Eigen::Ref<VecX> b) const {
  DemandReadyToSolve(b.size());
  SolveBlock(b.data(), b.size(), 1);
}

// Blocks of up to kMaxBlockColumns columns.
void CholmodCholesky::SolveColumns(Eigen::Ref<MatX> B) const {
  DemandReadyToSolve(B.rows());
  const Eigen::Index stride = B.outerStride();
  for (Eigen::Index c = 0; c < B.cols(); c += kMaxBlockColumns) {
    const int width = static_cast<int>(std::min<Eigen::Index>(kMaxBlockColumns, B.cols() - c));
    SolveBlock(B.data() + c * stride, stride, width);
  }
}

// gather Y = P B, forward L Z = Y and backward L^T W = Z (supernode by supernode, dtrsm and dgemm
// on the dense blocks), scatter B = P^T W.
void CholmodCholesky::SolveBlock(double* b, Eigen::Index outer_stride, int width) const {
  internal::CholmodState& state = *state_;
  const int* perm = perm_.data();
  double* y = state.y.data();
  for (int c = 0; c < width; ++c)
    for (int k = 0; k < n_; ++k) y[k + c * n_] = b[perm[k] + c * outer_stride];
  cholmod_dense Y = ViewDense(y, n_, width, n_);
  cholmod_dense E = ViewDense(state.e.data(), width, state.L->maxesize, width);
  cholmod_super_lsolve(state.L, &Y, &E, &state.common);
  cholmod_super_ltsolve(state.L, &Y, &E, &state.common);
  DemandCholmodOk(state.common, "Solve");
  for (int c = 0; c < width; ++c)
    for (int k = 0; k < n_; ++k) b[perm[k] + c * outer_stride] = y[k + c * n_];
}

double CholmodCholesky::stored_entries_in_L() const {
  return state_ && state_->L ? static_cast<double>(state_->L->xsize) : 0.0;
}

int CholmodCholesky::num_supernodes() const {
  return state_ && state_->L ? static_cast<int>(state_->L->nsuper) : 0;
}

}  // namespace taut

#else  // !TAUT_WITH_CHOLMOD: a stub that says how to get CHOLMOD.

namespace taut {

bool IsCholmodAvailable() { return false; }

namespace internal {
struct CholmodState {};
void CholmodStateDeleter::operator()(CholmodState* state) const { delete state; }
}  // namespace internal

namespace {
// Throws the InputError of every factor or solve call in a build without CHOLMOD.
[[noreturn]] void ThrowNoCholmod(const char* what) {
  throw InputError(internal::Concat(
      "CholmodCholesky::", what,
      ": this build of taut has no CHOLMOD (LinearSolverKind::kCholmod needs a build configured "
      "with -DTAUT_WITH_CHOLMOD=ON, which makes it GPL-2+; kAuto and kSparseLdlt work without)"));
}
}  // namespace

CholmodCholesky::CholmodCholesky() = default;
CholmodCholesky::~CholmodCholesky() = default;
CholmodCholesky::CholmodCholesky(CholmodCholesky&&) noexcept = default;
CholmodCholesky& CholmodCholesky::operator=(CholmodCholesky&&) noexcept = default;
void CholmodCholesky::Analyze(const SparseMatrix&) { ThrowNoCholmod("Analyze"); }
bool CholmodCholesky::Factorize(const SparseMatrix&) { ThrowNoCholmod("Factorize"); }
void CholmodCholesky::Solve(Eigen::Ref<VecX>) const { ThrowNoCholmod("Solve"); }
void CholmodCholesky::SolveColumns(Eigen::Ref<MatX>) const { ThrowNoCholmod("SolveColumns"); }
void CholmodCholesky::SolveBlock(double*, Eigen::Index, int) const { ThrowNoCholmod("Solve"); }
void CholmodCholesky::DemandReadyToSolve(Eigen::Index) const { ThrowNoCholmod("Solve"); }
double CholmodCholesky::stored_entries_in_L() const { return 0.0; }
int CholmodCholesky::num_supernodes() const { return 0; }

}  // namespace taut

#endif  // TAUT_WITH_CHOLMOD
