// Shared helpers for the tests: random states and central finite differences.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <functional>
#include <random>

#include "plugin/common.h"

namespace taut::testing {

// Random rotation from a random unit quaternion.
inline Mat3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

// Signed singular values in [lo, hi] sorted by |s| descending with pairwise gaps >= 0.1 (of
// s_a - s_b, hence also of s_a + s_b), s_3 negated (an inverted element) with probability
// inverted_fraction.
inline Vec3 RandomSeparatedSignedValues(std::mt19937& rng, double lo, double hi,
                                        double inverted_fraction) {
  std::uniform_real_distribution<double> u(lo, hi), coin(0.0, 1.0);
  while (true) {
    Vec3 s(u(rng), u(rng), u(rng));
    std::sort(s.data(), s.data() + 3, [](double a, double b) { return a > b; });
    if (s[0] - s[1] < 0.1 || s[1] - s[2] < 0.1) continue;
    if (coin(rng) < inverted_fraction) s[2] = -s[2];
    return s;
  }
}

// Central finite-difference Jacobian d f / d x (f: R^n -> R^m) with step h.
inline MatX CentralDifference(const std::function<VecX(const VecX&)>& f, const VecX& x, double h) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    VecX xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    J.col(k) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

// ||A - B|| / ||B||.
inline double RelativeError(const MatX& A, const MatX& B) { return (A - B).norm() / B.norm(); }

}  // namespace taut::testing
