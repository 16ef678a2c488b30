#include "plugin/polar_rotation.h"

#include <cmath>

#include "plugin/signed_svd.h"

namespace taut {
namespace {

// Newton's polar iteration gives up after this many steps (the SVD answers instead). With the
// Frobenius scaling it converges in 3-6 steps down to s_3 / s_1 ~ 1e-8 (measured).
constexpr int kMaxNewtonSteps = 10;
// Stop when ||X_{k+1} - X_k||_F^2 <= this: the step is about the distance to the limit, so the
// next distance is about its square over 2, ~5e-17.
constexpr double kStepSquaredTolerance = 1e-16;
// G with det G <= this times ||G||_F^3 (near singular: s_3 s_2 / s_1^2 below ~1e-12) go to the SVD:
// the first inverse would carry too few bits to say which rotation completes the rank-2 part.
constexpr double kMinRelativeDeterminant = 1e-12;
// Frobenius scaling pays while ||X^-1||_F^2 and ||X||_F^2 differ by more than this fraction.
constexpr double kScalingThreshold = 0.25;

// Cofactor matrix of X: X^-T = cof(X) / det X, det X = X.row(0) . cof(X).row(0).
Mat3 CalcCofactors(const Mat3& X) {
  Mat3 C;
  C(0, 0) = X(1, 1) * X(2, 2) - X(1, 2) * X(2, 1);
  C(0, 1) = X(1, 2) * X(2, 0) - X(1, 0) * X(2, 2);
  C(0, 2) = X(1, 0) * X(2, 1) - X(1, 1) * X(2, 0);
  C(1, 0) = X(0, 2) * X(2, 1) - X(0, 1) * X(2, 2);
  C(1, 1) = X(0, 0) * X(2, 2) - X(0, 2) * X(2, 0);
  C(1, 2) = X(0, 1) * X(2, 0) - X(0, 0) * X(2, 1);
  C(2, 0) = X(0, 1) * X(1, 2) - X(0, 2) * X(1, 1);
  C(2, 1) = X(0, 2) * X(1, 0) - X(0, 0) * X(1, 2);
  C(2, 2) = X(0, 0) * X(1, 1) - X(0, 1) * X(1, 0);
  return C;
}

// X <- 1/2 (zeta X + X^-T / zeta) for det X > min_relative_det ||X||_F^3 (Higham 1986, the
// scaled Newton iteration). Returns the squared step ||X_new - X||_F^2, or -1 when det X is not
// above that bound (or NaN).
double TakeNewtonPolarStep(Mat3& X, double min_relative_det) {
  const Mat3 C = CalcCofactors(X);
  const double det = X.row(0).dot(C.row(0));
  const double norm_x = X.squaredNorm();
  if (!(det > min_relative_det * norm_x * std::sqrt(norm_x))) return -1.0;
  // ||X^-1||_F^2 = ||C||_F^2 / det^2; zeta = (||X^-1||_F / ||X||_F)^(1/2).
  const double norm_inverse = C.squaredNorm() / (det * det);
  const double zeta = std::abs(norm_inverse - norm_x) > kScalingThreshold * norm_x
                          ? std::sqrt(std::sqrt(norm_inverse / norm_x))
                          : 1.0;
  const Mat3 next = (0.5 * zeta) * X + (0.5 / (zeta * det)) * C;
  const double step = (next - X).squaredNorm();
  X = next;
  return step;
}

}  // namespace

Mat3 CalcPolarRotation(const Mat3& G) {
  Mat3 X = G;
  for (int k = 0; k < kMaxNewtonSteps; ++k) {
    // Later iterates are better conditioned than G: only G itself is tested against the bound.
    const double step = TakeNewtonPolarStep(X, k == 0 ? kMinRelativeDeterminant : 0.0);
    if (step < 0.0) break;  // near singular, inverted or not finite: the signed SVD's rotation
    if (step <= kStepSquaredTolerance) return X;
  }
  return CalcPolarRotationBySvd(G);
}

}  // namespace taut
