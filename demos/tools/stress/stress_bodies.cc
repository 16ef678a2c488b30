#include "demos/tools/stress/stress_bodies.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "plugin/box_tet_mesher.h"

namespace taut::stress {

double CalcTetQuality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 p[4] = {a, b, c, d};
  double longest = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (p[i] - p[j]).norm());
  return CalcTetSignedVolume(a, b, c, d) / (longest * longest * longest);
}

namespace {
// Smallest quality over the listed tets of the mesh.
double CalcMinQuality(const TetMesh& mesh, const std::vector<int>& tets) {
  double q = HUGE_VAL;
  for (int t : tets) {
    const auto& e = mesh.tets[t];
    q = std::min(
        q, CalcTetQuality(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]], mesh.nodes[e[3]]));
  }
  return q;
}
}  // namespace

SliverMesh MakeSliverCubeMesh(double side, int n, double target_quality, const Vec3& min_corner) {
  TAUT_DEMAND(n >= 3, "MakeSliverCubeMesh: needs n >= 3 cells per side, got ", n);
  TAUT_DEMAND(target_quality > 0.0 && target_quality <= 0.01,
              "MakeSliverCubeMesh: target quality must be in (0, 0.01], got ", target_quality);
  SliverMesh out;
  out.mesh = MakeBoxTetMesh(Vec3::Constant(side), n, n, n, min_corner);
  out.mesh.source = "sliver cube";
  const int node = BoxNodeIndex(1, 1, 1, n, n);
  std::vector<int> star;
  for (int t = 0; t < static_cast<int>(out.mesh.tets.size()); ++t)
    if (std::count(out.mesh.tets[t].begin(), out.mesh.tets[t].end(), node) > 0) star.push_back(t);
  // Move the node along d: every incident volume is affine in t; the first to vanish bounds t.
  const Vec3 p0 = out.mesh.nodes[node];
  const Vec3 d = Vec3(1.0, 0.37, 0.11).normalized() * (side / n);
  const auto volume = [&](int t, double s) {
    out.mesh.nodes[node] = p0 + s * d;
    const auto& e = out.mesh.tets[t];
    return CalcTetSignedVolume(out.mesh.nodes[e[0]], out.mesh.nodes[e[1]], out.mesh.nodes[e[2]],
                               out.mesh.nodes[e[3]]);
  };
  double t_zero = HUGE_VAL;
  for (int t : star) {
    const double v0 = volume(t, 0.0), slope = volume(t, 1.0) - v0;
    if (slope < 0.0) t_zero = std::min(t_zero, -v0 / slope);
  }
  // Bisection on the smallest incident quality, from q(0) > target down to q(t_zero) = 0.
  double lo = 0.0, hi = t_zero;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    out.mesh.nodes[node] = p0 + mid * d;
    (CalcMinQuality(out.mesh, star) > target_quality ? lo : hi) = mid;
  }
  out.mesh.nodes[node] = p0 + lo * d;
  std::vector<int> all(out.mesh.tets.size());
  for (size_t t = 0; t < all.size(); ++t) all[t] = static_cast<int>(t);
  out.min_quality = CalcMinQuality(out.mesh, all);
  for (int t : star)
    if (CalcMinQuality(out.mesh, {t}) < 2.0 * target_quality) ++out.num_slivers;
  return out;
}

TetVolumeStats CalcTetVolumeStats(const TetMesh& mesh, const VecX& x) {
  TetVolumeStats stats;
  double rest_sum = 0.0, sum = 0.0;
  stats.min_volume_ratio = HUGE_VAL;
  for (const auto& e : mesh.tets) {
    const double rest =
        CalcTetSignedVolume(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]], mesh.nodes[e[3]]);
    const double now = CalcTetSignedVolume(x.segment<3>(3 * e[0]), x.segment<3>(3 * e[1]),
                                           x.segment<3>(3 * e[2]), x.segment<3>(3 * e[3]));
    rest_sum += rest;
    sum += now;
    if (now <= 0.0) ++stats.inverted;
    stats.min_volume_ratio = std::min(stats.min_volume_ratio, now / rest);
  }
  stats.volume_ratio = sum / rest_sum;
  return stats;
}

int CountInvertedHexes(const HexLattice& lattice, const VecX& x) {
  int inverted = 0;
  for (const auto& hex : lattice.hexes) {
    std::array<Vec3, 8> corners;
    for (int a = 0; a < 8; ++a) corners[a] = x.segment<3>(3 * hex[a]);
    bool bad = false;
    for (int q = 0; q < 8; ++q)
      bad = bad || CalcHexJacobian(corners, HexGaussPoint(q)).determinant() <= 0.0;
    if (bad) ++inverted;
  }
  return inverted;
}

DeformableBody* AddCubeBody(double side, int cells, bool hexes, const Vec3& min_corner,
                            const DeformableBodySettings& settings, DeformableWorld& world) {
  const Vec3 size = Vec3::Constant(side);
  if (hexes)
    return world.AddHexBody(MakeBoxHexLattice(size, cells, cells, cells, min_corner), settings);
  return world.AddTetBody(MakeBoxTetMesh(size, cells, cells, cells, min_corner), settings);
}

double CalcShapeError(const VecX& rest, const VecX& x, const VecX& mass, double size) {
  const int n = static_cast<int>(mass.size());
  Vec3 rest_c = Vec3::Zero(), c = Vec3::Zero();
  const double m = mass.sum();
  for (int i = 0; i < n; ++i) {
    rest_c += mass[i] * rest.segment<3>(3 * i) / m;
    c += mass[i] * x.segment<3>(3 * i) / m;
  }
  // Kabsch: H = sum m_i (x_i - c)(X_i - X_c)^T = U S V^T, best proper R = U diag(1, 1, det) V^T.
  Mat3 H = Mat3::Zero();
  for (int i = 0; i < n; ++i)
    H += mass[i] * (x.segment<3>(3 * i) - c) * (rest.segment<3>(3 * i) - rest_c).transpose();
  Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Mat3 R = svd.matrixU() * D * svd.matrixV().transpose();
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    sum +=
        mass[i] * (R * (rest.segment<3>(3 * i) - rest_c) - (x.segment<3>(3 * i) - c)).squaredNorm();
  return std::sqrt(sum / m) / size;
}

void MirrorPositions(const Vec3& point, const Vec3& normal, VecX& x) {
  const Vec3 u = normal.normalized();
  for (Eigen::Index i = 0; i < x.size() / 3; ++i)
    x.segment<3>(3 * i) -= 2.0 * u.dot(x.segment<3>(3 * i) - point) * u;
}

void SquashPositions(double z, VecX& x) {
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) x[3 * i + 2] = z;
}

Vec3 CalcCentreOfMass(const DeformableBody& body) {
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < body.num_nodes(); ++i) c += body.mass()[i] * body.node_position(i);
  return c / body.mass().sum();
}

Vec3 CalcLinearMomentum(const DeformableBody& body) {
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < body.num_nodes(); ++i) p += body.mass()[i] * body.v().segment<3>(3 * i);
  return p;
}

Vec3 CalcAngularMomentum(const DeformableBody& body) {
  const Vec3 c = CalcCentreOfMass(body);
  Vec3 L = Vec3::Zero();
  for (int i = 0; i < body.num_nodes(); ++i)
    L += body.mass()[i] * (body.node_position(i) - c).cross(body.v().segment<3>(3 * i));
  return L;
}

void SetRigidVelocity(const Vec3& v_c, const Vec3& w, DeformableBody& body) {
  const Vec3 c = CalcCentreOfMass(body);
  VecX v(3 * body.num_nodes());
  for (int i = 0; i < body.num_nodes(); ++i)
    v.segment<3>(3 * i) = v_c + w.cross(body.node_position(i) - c);
  body.set_v(v);
}

btRigidBody* AddDynamicBox(const Vec3& half_extents, double mass, const Vec3& centre,
                           BulletWorldHolder& holder) {
  holder.shapes.push_back(std::make_unique<btBoxShape>(
      btVector3(half_extents.x(), half_extents.y(), half_extents.z())));
  btCollisionShape* shape = holder.shapes.back().get();
  btVector3 inertia(0, 0, 0);
  shape->calculateLocalInertia(mass, inertia);
  btTransform pose;
  pose.setIdentity();
  pose.setOrigin(btVector3(centre.x(), centre.y(), centre.z()));
  holder.motion_states.push_back(std::make_unique<btDefaultMotionState>(pose));
  btRigidBody::btRigidBodyConstructionInfo info(mass, holder.motion_states.back().get(), shape,
                                                inertia);
  holder.rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  btRigidBody* box = holder.rigid_bodies.back().get();
  box->setActivationState(DISABLE_DEACTIVATION);
  holder.world.addRigidBody(box);
  return box;
}

}  // namespace taut::stress
