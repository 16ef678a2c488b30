// The dense kernel sets (plugin/dense_kernels.h): every kernel of every set this machine runs
// against a plain loop reference on blocks with leading dimensions larger than their rows, the
// Cholesky's failure column, and the choice by CPU and TAUT_DENSE_KERNELS.
#include "plugin/dense_kernels.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdlib>
#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {
namespace {

std::vector<const DenseKernels*> KernelSetsOfThisMachine() {
  std::vector<const DenseKernels*> sets = {&GenericDenseKernels()};
  if (Avx2DenseKernels() != nullptr) sets.push_back(Avx2DenseKernels());
  return sets;
}

// A column-major (rows x cols) block inside storage of leading dimension ld, random entries.
std::vector<double> RandomStorage(int ld, int cols, unsigned seed) {
  std::srand(seed);
  std::vector<double> v(static_cast<size_t>(ld) * cols);
  for (double& x : v) x = std::rand() / double(RAND_MAX) - 0.5;
  return v;
}

Eigen::MatrixXd ViewOf(const std::vector<double>& storage, int ld, int rows, int cols) {
  return Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>(storage.data(), rows, cols,
                                                                    Eigen::OuterStride<>(ld));
}

// An SPD (n x n) matrix: B B^T + n I.
Eigen::MatrixXd RandomSpd(int n, unsigned seed) {
  std::srand(seed);
  Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, n);
  return b * b.transpose() + n * Eigen::MatrixXd::Identity(n, n);
}

TEST(DenseKernelsTest, ProductsMatchPlainLoopsInEverySet) {
  for (const DenseKernels* kernels : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(kernels->name);
    // C (m x n) = A (m x k) B (n x k)^T, A and B inside taller storage.
    const int m = 37, n = 11, k = 300, lda = 41, ldb = 13, ldc = 40;
    const std::vector<double> a = RandomStorage(lda, k, 1), b = RandomStorage(ldb, k, 2);
    std::vector<double> c(static_cast<size_t>(ldc) * n, 7.0);
    kernels->multiply_by_transposed(a.data(), lda, b.data(), ldb, m, n, k, c.data(), ldc);
    const Eigen::MatrixXd a_m = ViewOf(a, lda, m, k), b_m = ViewOf(b, ldb, n, k);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (int p = 0; p < k; ++p) sum += a_m(i, p) * b_m(j, p);
        EXPECT_NEAR(c[j * ldc + i], sum, 1e-12 * k) << i << "," << j;
      }
    EXPECT_EQ(c[m], 7.0) << "wrote below the block";

    // a^T b and a^T a over a depth of more than two chunks.
    const int d = 2 * kDenseProductDepthChunk + 17, cols_a = 9, cols_b = 5;
    const std::vector<double> da = RandomStorage(d, cols_a, 3), db = RandomStorage(d, cols_b, 4);
    Eigen::MatrixXd ab(cols_a, cols_b), aa(cols_a, cols_a);
    kernels->multiply_transposed_by_chunks(da.data(), d, db.data(), d, d, cols_a, cols_b, ab.data(),
                                           cols_a);
    kernels->gram_by_chunks(da.data(), d, d, cols_a, aa.data(), cols_a);
    const Eigen::MatrixXd da_m = ViewOf(da, d, d, cols_a), db_m = ViewOf(db, d, d, cols_b);
    for (int i = 0; i < cols_a; ++i) {
      for (int j = 0; j < cols_b; ++j) {
        double sum = 0.0;
        for (int p = 0; p < d; ++p) sum += da_m(p, i) * db_m(p, j);
        EXPECT_NEAR(ab(i, j), sum, 1e-12 * d);
      }
      for (int j = 0; j < cols_a; ++j) {
        double sum = 0.0;
        for (int p = 0; p < d; ++p) sum += da_m(p, i) * da_m(p, j);
        EXPECT_NEAR(aa(i, j), sum, 1e-12 * d) << "both triangles";
      }
    }
  }
}

TEST(DenseKernelsTest, HexElementKernelsMatchPlainLoopsInEverySet) {
  // K (24 x 24) symmetric as the hex element's K_e, R a rotation, u random.
  Eigen::MatrixXd K = RandomSpd(24, 5);
  const Eigen::VectorXd u = Eigen::VectorXd::Random(24);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const double scale = 0.37;
  for (const DenseKernels* kernels : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(kernels->name);
    Eigen::VectorXd Ku(24);
    kernels->multiply_hex_stiffness(K.data(), u.data(), Ku.data());
    for (int i = 0; i < 24; ++i) {
      double sum = 0.0;
      for (int j = 0; j < 24; ++j) sum += K(i, j) * u[j];
      EXPECT_NEAR(Ku[i], sum, 1e-12 * 24 * K.norm()) << "row " << i;
    }
    std::vector<double> blocks(64 * 9, 0.0);
    kernels->rotate_hex_stiffness_blocks(K.data(), R.data(), scale, blocks.data());
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const Eigen::Matrix3d expected =
            scale * R * K.block<3, 3>(3 * a, 3 * b) * R.transpose();  // every block, both halves
        const Eigen::Map<const Eigen::Matrix3d> block(blocks.data() + 9 * (8 * a + b));
        EXPECT_LT((block - expected).norm(), 1e-13 * K.norm()) << "block " << a << ", " << b;
      }
  }
}

TEST(DenseKernelsTest, CholeskyAndTriangularSolvesInvertThePanelInEverySet) {
  for (const DenseKernels* kernels : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(kernels->name);
    // A panel (w + below rows, w columns): SPD diagonal block, then rows below.
    const int w = 70, below = 45, ld = w + below;
    const Eigen::MatrixXd spd = RandomSpd(w, 5);
    std::srand(6);
    const Eigen::MatrixXd rest = Eigen::MatrixXd::Random(below, w);
    Eigen::MatrixXd panel(ld, w);
    panel << spd, rest;
    ASSERT_EQ(kernels->cholesky_lower(panel.data(), ld, w), -1);
    kernels->solve_right_lower_transposed(panel.data(), ld, w, panel.data() + w, ld, below);
    const Eigen::MatrixXd l = panel.topRows(w).triangularView<Eigen::Lower>();
    EXPECT_LT((l * l.transpose() - spd).norm(), 1e-10 * spd.norm());
    EXPECT_LT((panel.bottomRows(below) * l.transpose() - rest).norm(), 1e-10 * rest.norm());

    // Forward then backward supernode solves, one column and a row-major block of 3.
    for (int cols : {1, 3}) {
      SCOPED_TRACE(cols);
      std::srand(7);
      const Eigen::MatrixXd y0 = Eigen::MatrixXd::Random(w, cols);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> y = y0;
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> t(below, cols);
      kernels->forward_supernode(panel.data(), ld, w, below, y.data(), cols, t.data());
      const Eigen::MatrixXd z = l.triangularView<Eigen::Lower>().solve(y0);
      EXPECT_LT((Eigen::MatrixXd(y) - z).norm(), 1e-10 * z.norm());
      EXPECT_LT((Eigen::MatrixXd(t) - panel.bottomRows(below) * z).norm(), 1e-10 * z.norm());
      // y_s -= L_below^T t; y_s = L^-T y_s.
      std::srand(8);
      const Eigen::MatrixXd t0 = Eigen::MatrixXd::Random(below, cols);
      t = t0;
      Eigen::MatrixXd expected = z - panel.bottomRows(below).transpose() * t0;
      expected = l.transpose().triangularView<Eigen::Upper>().solve(expected);
      kernels->backward_supernode(panel.data(), ld, w, below, y.data(), cols, t.data());
      EXPECT_LT((Eigen::MatrixXd(y) - expected).norm(), 1e-10 * expected.norm());
    }
  }
}

TEST(DenseKernelsTest, SinglePrecisionPanelSolvesInvertTheFloatPanelInEverySet) {
  // The kept factor's panels in fl32 (m rows, w columns, column-major, no padding), u in double:
  // forward u_t = L_tt^-1 u_t, u_rest -= L_rest u_t; backward u_t = L_tt^-T (u_t - L_rest^T
  // u_rest), against the same solves in double on the float entries. w = 7 covers the blocked
  // passes of 4 columns and the single columns after them.
  for (const DenseKernels* kernels : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(kernels->name);
    for (const int w : {7, 8}) {
      SCOPED_TRACE(w);
      const int below = 29, m = w + below;
      const Eigen::MatrixXd spd = RandomSpd(w, 11);
      std::srand(12);
      Eigen::MatrixXd panel(m, w);
      panel << Eigen::MatrixXd(spd.llt().matrixL()), Eigen::MatrixXd::Random(below, w);
      const Eigen::MatrixXf single = panel.cast<float>();
      const Eigen::MatrixXd l = single.cast<double>();  // what the kernels multiply by
      const Eigen::MatrixXd l_tt = l.topRows(w).triangularView<Eigen::Lower>();
      std::srand(13);
      const Eigen::VectorXd u0 = Eigen::VectorXd::Random(m);

      Eigen::VectorXd u = u0;
      kernels->forward_panel_single(single.data(), m, w, u.data());
      const Eigen::VectorXd top = l_tt.triangularView<Eigen::Lower>().solve(u0.head(w));
      EXPECT_LT((u.head(w) - top).norm(), 1e-12 * top.norm());
      const Eigen::VectorXd rest = u0.tail(below) - l.bottomRows(below) * top;
      EXPECT_LT((u.tail(below) - rest).norm(), 1e-12 * rest.norm());

      u = u0;
      kernels->backward_panel_single(single.data(), m, w, u.data());
      const Eigen::VectorXd rhs = u0.head(w) - l.bottomRows(below).transpose() * u0.tail(below);
      const Eigen::VectorXd expected = l_tt.transpose().triangularView<Eigen::Upper>().solve(rhs);
      EXPECT_LT((u.head(w) - expected).norm(), 1e-12 * expected.norm());
      EXPECT_EQ(u.tail(below), u0.tail(below)) << "the rows below are read, not written";
    }
  }
}

// Eigen blocks a product's depth by the L1 size it is told, and each block is summed on its own:
// the cache sizes are part of the result. Every set runs with kEigenCacheSizes from load on, so
// a product is the same bits on any CPU. Told another CPU's sizes, the same deep product rounds
// differently: an Intel Xeon's 48 KiB L1d changes the AVX2 set's depth blocks (208 -> 336 of the
// 1,000), a 64 KiB L1d both sets' (generic 504 -> 1,000).
TEST(DenseKernelsTest, ProductsRoundForTheFixedCacheSizesOnAnyCpu) {
  const int m = 24, n = 20, k = 1000;  // k spans several depth blocks for either L1
  const std::vector<double> a = RandomStorage(m, k, 61), b = RandomStorage(n, k, 62);
  for (const DenseKernels* set : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(set->name);
    EXPECT_EQ(set->l1_cache_size(), kEigenCacheSizes.l1);  // set when taut loaded
    const auto product = [&] {
      std::vector<double> c(static_cast<size_t>(m) * n);
      set->multiply_by_transposed(a.data(), m, b.data(), n, m, n, k, c.data(), m);
      return c;
    };
    const std::vector<double> fixed = product();
    const std::ptrdiff_t other_l1 = std::string(set->name) == "avx2" ? 48 * 1024 : 64 * 1024;
    SetEigenCacheSizes({other_l1, 2048 * 1024, 480 * 1024 * 1024});
    const std::vector<double> other = product();
    SetEigenCacheSizes(kEigenCacheSizes);
    EXPECT_NE(other, fixed) << "an L1 of " << other_l1 << " bytes did not change the rounding";
    EXPECT_EQ(product(), fixed);
    // Both are the product to round-off.
    EXPECT_LT((ViewOf(other, m, m, n) - ViewOf(fixed, m, m, n)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(DenseKernelsTest, CholeskyReportsTheFirstColumnWithoutAPositivePivot) {
  for (const DenseKernels* kernels : KernelSetsOfThisMachine()) {
    SCOPED_TRACE(kernels->name);
    const int n = 40, bad = 23;
    Eigen::MatrixXd a = RandomSpd(n, 9);
    // Column `bad` made a copy of column 3 (and so its row): singular from that pivot on.
    a.col(bad) = a.col(3);
    a.row(bad) = a.row(3);
    EXPECT_EQ(kernels->cholesky_lower(a.data(), n, n), bad);
  }
}

TEST(DenseKernelsTest, TheChoiceFollowsTheCpuAndTheEnvironment) {
  EXPECT_STREQ(GenericDenseKernels().name, "generic");
  if (Avx2DenseKernels() != nullptr) EXPECT_STREQ(Avx2DenseKernels()->name, "avx2");
  EXPECT_EQ(ChooseDenseKernels("", true), "avx2");
  EXPECT_EQ(ChooseDenseKernels("", false), "generic");
  EXPECT_EQ(ChooseDenseKernels("generic", true), "generic");
  EXPECT_EQ(ChooseDenseKernels("avx2", true), "avx2");
  try {
    ChooseDenseKernels("avx2", false);
    ADD_FAILURE() << "avx2 without the CPU support accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("TAUT_DENSE_KERNELS=avx2"), std::string::npos) << e.what();
  }
  try {
    ChooseDenseKernels("sse9", true);
    ADD_FAILURE() << "unknown set accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'sse9'"), std::string::npos) << e.what();
  }
  // The active set is one of the two, and avx2 whenever the machine has it and nothing forced it.
  const std::string active = ActiveDenseKernels().name;
  EXPECT_TRUE(active == "generic" || active == "avx2");
  if (std::getenv("TAUT_DENSE_KERNELS") == nullptr)
    EXPECT_EQ(active, Avx2DenseKernels() != nullptr ? "avx2" : "generic");
}

}  // namespace
}  // namespace taut
