#include "plugin/corotated_hex_element.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "plugin/dense_kernels.h"
#include "plugin/polar_rotation.h"

namespace taut {

namespace {
// [x_b - x_a, x_c - x_a, x_d - x_a] for inscribed tet t.
Mat3 TetEdges(const HexNodes& x, int t) {
  const int* n = kHexInscribedTets[t];
  Mat3 D;
  for (int c = 0; c < 3; ++c) D.col(c) = x[n[c + 1]] - x[n[0]];
  return D;
}
}  // namespace

HexRestElement CalcHexRestElement(const HexNodes& X, const LameParameters& lame) {
  HexRestElement rest;
  rest.X = X;
  rest.volume = 0.0;
  Mat24 stiffness = Mat24::Zero();
  for (int q = 0; q < 8; ++q) {
    const Vec3 s = HexGaussPoint(q);
    const Mat3 F = CalcHexJacobian(X, s);
    const double det = F.determinant();
    TAUT_DEMAND(det > 0.0, "hex element: det dX/ds = ", det, " <= 0 at Gauss point ", q);
    rest.gradients[q] = CalcHexShapeGradients(s) * F.inverse();
    rest.weights[q] = det;
    rest.volume += det;
    // K_e += w det F B^T C B; block (a,b) = lambda g_a g_b^T + mu g_b g_a^T + mu (g_a.g_b) I.
    const HexGradients& g = rest.gradients[q];
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const Vec3 ga = g.row(a).transpose(), gb = g.row(b).transpose();
        Mat3 K = lame.lambda * ga * gb.transpose() + lame.mu * gb * ga.transpose();
        K.diagonal().array() += lame.mu * ga.dot(gb);
        stiffness.block<3, 3>(3 * a, 3 * b) += det * K;
      }
  }
  // K_ba = K_ab^T holds to rounding; exactly after this (CalcRotatedHexStiffnessBlocks uses it).
  rest.shared_stiffness = std::make_shared<const Mat24>(0.5 * (stiffness + stiffness.transpose()));
  rest.stiffness_norm_bound = rest.stiffness().cwiseAbs().rowwise().sum().maxCoeff() * (1.0 + 1e-7);
  rest.center_gradients =
      CalcHexShapeGradients(Vec3::Zero()) * CalcHexJacobian(X, Vec3::Zero()).inverse();
  for (int t = 0; t < 2; ++t) rest.tet_rest_inverses[t] = TetEdges(X, t).inverse();
  return rest;
}

namespace {
// Hash of K's entries rounded to 2^-24 max|K|: equal matrices up to rounding land in one bucket
// unless an entry sits on a rounding boundary (then they are not shared, which is only slower).
std::uint64_t HashRoundedStiffness(const Mat24& K) {
  const double quantum = std::ldexp(K.cwiseAbs().maxCoeff(), -24);
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  if (!(quantum > 0.0)) return hash;            // a zero (or non-finite) K_e: one bucket
  for (int i = 0; i < 24 * 24; ++i) {
    const auto rounded = static_cast<std::uint64_t>(std::llround(K.data()[i] / quantum));
    hash = (hash ^ rounded) * 1099511628211ull;
  }
  return hash;
}

bool StiffnessesAgree(const Mat24& A, const Mat24& B) {
  const double scale = std::max(A.cwiseAbs().maxCoeff(), B.cwiseAbs().maxCoeff());
  return (A - B).cwiseAbs().maxCoeff() <= kSharedHexStiffnessTolerance * scale;
}
}  // namespace

void ShareEqualHexStiffnesses(std::vector<HexRestElement>& elements) {
  std::unordered_map<std::uint64_t, std::vector<int>> firsts;  // hash -> elements sharing theirs
  for (int e = 0; e < static_cast<int>(elements.size()); ++e) {
    std::vector<int>& candidates = firsts[HashRoundedStiffness(elements[e].stiffness())];
    bool shared = false;
    for (int first : candidates)
      if (StiffnessesAgree(elements[first].stiffness(), elements[e].stiffness())) {
        elements[e].shared_stiffness = elements[first].shared_stiffness;
        shared = true;
        break;
      }
    if (!shared) candidates.push_back(e);
  }
}

Mat3 CalcHexDeformationGradient(const HexGradients& g, const HexNodes& x) {
  Mat3 G = Mat3::Zero();
  for (int a = 0; a < 8; ++a) G += x[a] * g.row(a);
  return G;
}

Mat3 CalcHexCenterDeformationGradient(const HexRestElement& rest, const HexNodes& x) {
  return CalcHexDeformationGradient(rest.center_gradients, x);
}

Mat3 CalcHexInscribedTetDeformationGradient(const HexRestElement& rest, const HexNodes& x, int t) {
  TAUT_ASSERT(t == 0 || t == 1);
  return TetEdges(x, t) * rest.tet_rest_inverses[t];
}

Mat3 CalcHexRotationGradient(const HexRestElement& rest, const HexNodes& x,
                             HexRotationMethod method) {
  return method == HexRotationMethod::kCenterPolar
             ? CalcHexCenterDeformationGradient(rest, x)
             : CalcHexInscribedTetDeformationGradient(rest, x, 0);
}

Mat3 CalcHexRotation(const HexRestElement& rest, const HexNodes& x, HexRotationMethod method) {
  return CalcPolarRotation(CalcHexRotationGradient(rest, x, method));
}

Mat3 CalcHexGaussStrain(const HexRestElement& rest, const HexNodes& x, const Mat3& R, int q) {
  const Mat3 RtG = R.transpose() * CalcHexDeformationGradient(rest.gradients[q], x);
  return 0.5 * (RtG + RtG.transpose()) - Mat3::Identity();
}

namespace {
// sum_a x_a / 8, summed in node order (the same bits wherever it is taken).
Vec3 CalcHexCentroid(const HexNodes& x) {
  Vec3 c = Vec3::Zero();
  for (int a = 0; a < 8; ++a) c += x[a] / 8.0;
  return c;
}

// u = R^T x - X, node-major, taken relative to the centroids (K_e annihilates translations),
// u_a = R^T (x_a - x_c) - (X_a - X_c), so far-from-origin elements keep full precision.
Vec24 CorotatedDisplacement(const HexRestElement& rest, const HexNodes& x, const Mat3& R) {
  const Vec3 xc = CalcHexCentroid(x), Xc = CalcHexCentroid(rest.X);
  Vec24 u;
  for (int a = 0; a < 8; ++a) u.segment<3>(3 * a) = R.transpose() * (x[a] - xc) - (rest.X[a] - Xc);
  return u;
}
}  // namespace

double CalcCorotatedHexEnergyBound(const HexRestElement& rest, const HexNodes& x, const Mat3& G) {
  if (!(G.determinant() > 0.0)) return HUGE_VAL;
  // ||G - R||_2 = max_i |s_i - 1| <= max_i |s_i^2 - 1| <= ||G^T G - I||_F (s_i > 0).
  const double rotation_gap = (G.transpose() * G - Mat3::Identity()).norm();
  const Vec3 xc = CalcHexCentroid(x), Xc = CalcHexCentroid(rest.X);
  double u_squared = 0.0;  // sum_a (bound on ||u_a||)^2
  for (int a = 0; a < 8; ++a) {
    const Vec3 X_a = rest.X[a] - Xc;
    const double u_a = ((x[a] - xc) - G * X_a).norm() + rotation_gap * X_a.norm();
    u_squared += u_a * u_a;
  }
  return 0.5 * rest.stiffness_norm_bound * u_squared;
}

double CalcCorotatedHexEnergy(const HexRestElement& rest, const HexNodes& x, const Mat3& R) {
  const Vec24 u = CorotatedDisplacement(rest, x, R);
  Vec24 Ku;
  ActiveDenseKernels().multiply_hex_stiffness(rest.stiffness().data(), u.data(), Ku.data());
  return 0.5 * u.dot(Ku);
}

Vec24 CalcCorotatedHexForces(const HexRestElement& rest, const HexNodes& x, const Mat3& R) {
  Vec24 f;
  CalcCorotatedHexForcesAndEnergy(rest, x, R, f);
  return f;
}

double CalcCorotatedHexForcesAndEnergy(const HexRestElement& rest, const HexNodes& x, const Mat3& R,
                                       Vec24& forces) {
  // f_a = -R (K_e u)_a, U = 1/2 u . K_e u.
  const Vec24 u = CorotatedDisplacement(rest, x, R);
  Vec24 Ku;
  ActiveDenseKernels().multiply_hex_stiffness(rest.stiffness().data(), u.data(), Ku.data());
  for (int a = 0; a < 8; ++a) forces.segment<3>(3 * a) = -(R * Ku.segment<3>(3 * a));
  return 0.5 * u.dot(Ku);
}

void CalcRotatedHexStiffnessBlocks(const HexRestElement& rest, const Mat3& R, double scale,
                                   HexStiffnessBlocks& blocks) {
  static_assert(sizeof(HexStiffnessBlocks) == 64 * 9 * sizeof(double), "blocks are contiguous");
  ActiveDenseKernels().rotate_hex_stiffness_blocks(rest.stiffness().data(), R.data(), scale,
                                                   blocks[0].data());
}

Mat24 CalcFrozenRotationHexStiffness(const HexRestElement& rest, const Mat3& R) {
  HexStiffnessBlocks blocks;
  CalcRotatedHexStiffnessBlocks(rest, R, 1.0, blocks);
  Mat24 K;
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b) K.block<3, 3>(3 * a, 3 * b) = blocks[8 * a + b];
  return K;
}

}  // namespace taut
