// What every ElementModel promises (plugin/element_model.h), checked through the interface alone
// on a small distorted tet body and hex body (both hex rotation methods):
//   f = -dU/dx,  K = -df/dx with the rotations held,  no response to a rigid motion,
//   lumped mass = density x rest volume, element rest volumes summing to the body's volume.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::RandomRotation;

const Material kMaterial{1e5, 0.3, 1000};
const Vec3 kBoxSize(0.2, 0.15, 0.1);
constexpr int kCells = 2;  // per axis: 27 nodes, one of them inside the box
// Rest shape = kRestShape (box nodes, the inner node moved by kInnerShift cells) + kRestOffset.
const Mat3 kRestShape = (Mat3() << 1.1, 0.2, 0.0, 0.0, 0.9, 0.1, 0.05, 0.0, 1.0).finished();
const Vec3 kInnerShift(0.2, -0.15, 0.1);
const Vec3 kRestOffset(0.3, -0.1, 0.2);

// Rest volume of the body [m^3]: moving the inner node keeps the box tiled, the linear map
// scales volumes by its determinant.
double BodyVolume() { return kRestShape.determinant() * kBoxSize.prod(); }

// The box grid's nodes distorted into the rest shape.
void DistortRestNodes(std::vector<Vec3>& nodes) {
  const Vec3 cell = kBoxSize / kCells;
  const Vec3 centre = 0.5 * kBoxSize;
  for (Vec3& X : nodes) {
    if ((X - centre).norm() < 1e-9) X += kInnerShift.cwiseProduct(cell);
    X = kRestShape * X + kRestOffset;
  }
}

// The bodies under test. kNonAffine: amplitude of the non-affine part of the deformation at
// which the forces are the exact gradient of CalcEnergy (whose rotations follow x). A tet is
// affine whatever the nodes do; a hex's force is -dU/dx with R held, the total gradient only
// where dU/dR = 0, i.e. under an affine deformation (R^T G symmetric at every Gauss point).
struct TetBody {
  static constexpr double kNonAffine = 1.0;
  static std::unique_ptr<ElementModel> Make() {
    auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(kBoxSize, kCells, kCells, kCells));
    DistortRestNodes(mesh->nodes);
    return std::make_unique<TetElementModel>(mesh, kMaterial);
  }
};

template <HexRotationMethod kMethod>
struct HexBody {
  static constexpr double kNonAffine = 0.0;
  static std::unique_ptr<ElementModel> Make() {
    auto lattice =
        std::make_shared<HexLattice>(MakeBoxHexLattice(kBoxSize, kCells, kCells, kCells));
    DistortRestNodes(lattice->nodes);
    return std::make_unique<HexElementModel>(lattice, kMaterial, kMethod);
  }
};

using CenterPolarHexBody = HexBody<HexRotationMethod::kCenterPolar>;
using InscribedTetHexBody = HexBody<HexRotationMethod::kInscribedTet>;

struct BodyName {
  template <typename Body>
  static std::string GetName(int) {
    if (std::is_same_v<Body, TetBody>) return "Tet";
    if (std::is_same_v<Body, CenterPolarHexBody>) return "HexCenterPolar";
    return "HexInscribedTet";
  }
};

template <typename Body>
class ElementModelConformanceTest : public ::testing::Test {
 protected:
  ElementModelConformanceTest() : model_(Body::Make()), n_(3 * model_->num_nodes()) {}

  // Node i of the rest shape.
  Vec3 Rest(int i) const { return model_->rest_positions().template segment<3>(3 * i); }

  // x = Q (F X + non_affine d(X)) + t: a random rotation Q and translation t of the rest shape
  // stretched and sheared by F, the nodes also moved by up to non_affine 4 % of a cell.
  VecX Deform(double strain, double non_affine) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mat3 F = Mat3::Identity();
    for (int k = 0; k < 9; ++k) F.data()[k] += strain * u(rng_);
    const Mat3 Q = RandomRotation(rng_);
    const Vec3 t(u(rng_), u(rng_), u(rng_));
    const double shift = 0.04 * non_affine * kBoxSize.minCoeff() / kCells;
    VecX x(n_);
    for (int i = 0; i < model_->num_nodes(); ++i) {
      const Vec3 d(u(rng_), u(rng_), u(rng_));
      x.template segment<3>(3 * i) = Q * (F * Rest(i) + shift * d) + t;
    }
    return x;
  }

  // Elastic forces at x (rotations updated at x) [N].
  VecX Forces(const VecX& x) {
    VecX f = VecX::Zero(n_);
    model_->UpdateRotationsAndAddForces(x, f);
    return f;
  }

  // Forces at x with the rotations of the last update held [N].
  VecX HeldRotationForces(const VecX& x) const {
    VecX f = VecX::Zero(n_);
    model_->AddHeldRotationForces(x, f);
    return f;
  }

  // K v with the rotations of the last update [N].
  VecX StiffnessTimes(const VecX& v) const {
    VecX Kv = VecX::Zero(n_);
    model_->AddScaledStiffnessTimes(1.0, v, Kv);
    return Kv;
  }

  // Dense K of the last update through AddScaledStiffness's index map (column-major entries).
  MatX AssembleStiffness() const {
    const int m = model_->nodes_per_element();
    std::vector<int> map;
    for (int e = 0; e < model_->num_elements(); ++e) {
      const int* nodes = model_->element_nodes(e);
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b)
          for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) map.push_back((3 * nodes[b] + c) * n_ + 3 * nodes[a] + r);
    }
    MatX K = MatX::Zero(n_, n_);
    model_->AddScaledStiffness(1.0, map, K.data());
    return K;
  }

  // The element stiffnesses at x (CalcElementStiffness) assembled into a dense 3N x 3N matrix.
  MatX AssembleElementStiffnesses(const VecX& x) const {
    const int m = model_->nodes_per_element();
    MatX K = MatX::Zero(n_, n_);
    ElementMatrix Ke;
    for (int e = 0; e < model_->num_elements(); ++e) {
      model_->CalcElementStiffness(e, x, Ke);
      EXPECT_EQ(Ke.rows(), 3 * m);
      const int* nodes = model_->element_nodes(e);
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b)
          K.block<3, 3>(3 * nodes[a], 3 * nodes[b]) += Ke.block<3, 3>(3 * a, 3 * b);
    }
    return K;
  }

  // The element forces at x (CalcElementForces) scattered into a 3N vector; energy = sum U_e.
  VecX ScatterElementForces(const VecX& x, double& energy) const {
    VecX f = VecX::Zero(n_);
    energy = 0.0;
    ElementVectors fe;
    for (int e = 0; e < model_->num_elements(); ++e) {
      energy += model_->CalcElementForces(e, x, fe);
      EXPECT_EQ(model_->CalcElementEnergy(e, x), model_->CalcElementForces(e, x, fe));
      for (int a = 0; a < model_->nodes_per_element(); ++a)
        f.template segment<3>(3 * model_->element_nodes(e)[a]) += fe[a];
    }
    return f;
  }

  // A rigid velocity w x (x - c) + v of the nodes at x.
  VecX RigidVelocity(const VecX& x) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Vec3 w(u(rng_), u(rng_), u(rng_)), v(u(rng_), u(rng_), u(rng_)), c(u(rng_), 0.0, 0.0);
    VecX velocity(n_);
    for (int i = 0; i < model_->num_nodes(); ++i)
      velocity.template segment<3>(3 * i) = w.cross(x.template segment<3>(3 * i) - c) + v;
    return velocity;
  }

  std::unique_ptr<ElementModel> model_;
  int n_;
  std::mt19937 rng_{15};
};

using Bodies = ::testing::Types<TetBody, CenterPolarHexBody, InscribedTetHexBody>;
TYPED_TEST_SUITE(ElementModelConformanceTest, Bodies, BodyName);

TYPED_TEST(ElementModelConformanceTest, ForcesAreMinusTheEnergyGradient) {
  ElementModel& model = *this->model_;
  const VecX x = this->Deform(0.15, TypeParam::kNonAffine);
  VecX f = VecX::Zero(this->n_);
  const double energy = model.UpdateRotationsAndAddForces(x, f);
  ASSERT_GT(energy, 1.0);  // a strain of ~15 % in 1e5 Pa over 3e-3 m^3
  EXPECT_NEAR(model.CalcEnergy(x), energy, 1e-12 * energy);
  // -dU/dx by central differences of CalcEnergy (rotations recomputed at every x).
  const double h = 1e-7;
  VecX gradient(this->n_);
  for (int k = 0; k < this->n_; ++k) {
    VecX xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    gradient[k] = (model.CalcEnergy(xp) - model.CalcEnergy(xm)) / (2.0 * h);
  }
  EXPECT_LT((f + gradient).norm(), 1e-6 * f.norm()) << "f\n" << f << "\n-dU/dx\n" << -gradient;
  // The per-element calls give the same forces and energies.
  double element_energy = 0.0;
  const VecX element_forces = this->ScatterElementForces(x, element_energy);
  EXPECT_NEAR(element_energy, energy, 1e-12 * energy);
  EXPECT_LT((element_forces - f).norm(), 1e-12 * f.norm());
}

TYPED_TEST(ElementModelConformanceTest, StiffnessIsMinusTheForceJacobianWithRotationsHeld) {
  const VecX x = this->Deform(0.15, 1.0);
  const VecX f = this->Forces(x);
  // Held at x the rotations give back x's forces, so K0 (R^T x - X) is the elastic force model.
  EXPECT_LT((this->HeldRotationForces(x) - f).norm(), 1e-10 * f.norm());
  // K v = -(f(x + h v) - f(x - h v)) / 2h with the rotations held (f is then linear in x).
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX v(this->n_);
  for (int k = 0; k < this->n_; ++k) v[k] = u(this->rng_);
  const double h = 1e-4;
  const VecX difference =
      (this->HeldRotationForces(x + h * v) - this->HeldRotationForces(x - h * v)) / (2.0 * h);
  const VecX Kv = this->StiffnessTimes(v);
  ASSERT_GT(Kv.norm(), 1e3);  // ~ E L |v|
  EXPECT_LT((Kv + difference).norm(), 1e-8 * Kv.norm());
  // The assembled K is that product, symmetric, and the per-element K_e at x add up to it.
  const MatX K = this->AssembleStiffness();
  EXPECT_LT((K * v - Kv).norm(), 1e-12 * Kv.norm());
  EXPECT_LT((K - K.transpose()).norm(), 1e-12 * K.norm());
  EXPECT_LT((this->AssembleElementStiffnesses(x) - K).norm(), 1e-12 * K.norm());
}

TYPED_TEST(ElementModelConformanceTest, StiffnessAlongTheForcesIsTheElementStiffnessQuadraticForm) {
  // CalcElementForcesAndStiffnessAlong: the forces and energy of CalcElementForces, and
  // f^T K_e f with K_e = CalcElementStiffness (its rotation from the same x).
  const ElementModel& model = *this->model_;
  const VecX x = this->Deform(0.15, TypeParam::kNonAffine);
  const int m = model.nodes_per_element();
  for (int e = 0; e < model.num_elements(); ++e) {
    ElementVectors forces, along_forces;
    const double energy = model.CalcElementForces(e, x, forces);
    double f_K_f = -1.0;
    EXPECT_EQ(model.CalcElementForcesAndStiffnessAlong(e, x, along_forces, &f_K_f), energy);
    VecX f(3 * m);
    for (int a = 0; a < m; ++a) {
      EXPECT_EQ(along_forces[a], forces[a]) << "element " << e << " node " << a;
      f.segment<3>(3 * a) = forces[a];
    }
    ElementMatrix K;
    model.CalcElementStiffness(e, x, K);
    const double expected = f.dot(K * f);
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(f_K_f, expected, 1e-12 * expected) << "element " << e;
  }
}

TYPED_TEST(ElementModelConformanceTest, StiffnessIsTheForceJacobianAtARigidPose) {
  // At x = Q X + t the derivative of the rotations adds nothing: -df/dx = K exactly, with the
  // rotations following x.
  const VecX x = this->Deform(0.0, 0.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX v(this->n_);
  for (int k = 0; k < this->n_; ++k) v[k] = u(this->rng_);
  const double h = 1e-6;
  const VecX difference = (this->Forces(x + h * v) - this->Forces(x - h * v)) / (2.0 * h);
  this->Forces(x);
  const VecX Kv = this->StiffnessTimes(v);
  ASSERT_GT(Kv.norm(), 1e3);
  EXPECT_LT((Kv + difference).norm(), 1e-6 * Kv.norm());
}

TYPED_TEST(ElementModelConformanceTest, RigidMotionHasNoEnergyForceOrStiffnessResponse) {
  ElementModel& model = *this->model_;
  const VecX x = this->Deform(0.0, 0.0);
  VecX f = VecX::Zero(this->n_);
  const double energy = model.UpdateRotationsAndAddForces(x, f);
  // Scales: E V for energies, E L^2 for forces (a unit strain would give them).
  const double E = kMaterial.youngs_modulus, L = kBoxSize.maxCoeff();
  EXPECT_LT(std::abs(energy), 1e-18 * E * BodyVolume());
  EXPECT_LT(std::abs(model.CalcEnergy(x)), 1e-18 * E * BodyVolume());
  EXPECT_LT(f.norm(), 1e-10 * E * L * L);
  double element_energy = 0.0;
  EXPECT_LT(this->ScatterElementForces(x, element_energy).norm(), 1e-10 * E * L * L);
  EXPECT_LT(std::abs(element_energy), 1e-18 * E * BodyVolume());
  // A rigid velocity of the pose strains nothing, a random one does.
  const VecX rigid = this->RigidVelocity(x);
  VecX random(this->n_);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < this->n_; ++k) random[k] = u(this->rng_) * rigid.norm() / std::sqrt(this->n_);
  const double response = this->StiffnessTimes(random).norm();
  ASSERT_GT(response, 1e3);
  EXPECT_LT(this->StiffnessTimes(rigid).norm(), 1e-10 * response);
}

TYPED_TEST(ElementModelConformanceTest, LumpedMassIsDensityTimesTheRestVolume) {
  const ElementModel& model = *this->model_;
  double volume = 0.0;
  for (int e = 0; e < model.num_elements(); ++e) {
    EXPECT_GT(model.element_rest_volume(e), 0.0) << "element " << e;
    volume += model.element_rest_volume(e);
  }
  EXPECT_NEAR(volume, BodyVolume(), 1e-12 * BodyVolume());
  VecX mass;
  model.CalcLumpedMass(kMaterial.density, mass);
  ASSERT_EQ(mass.size(), model.num_nodes());
  EXPECT_GT(mass.minCoeff(), 0.0);
  EXPECT_NEAR(mass.sum(), kMaterial.density * BodyVolume(), 1e-12 * kMaterial.density * volume);
  // Each element gives every one of its nodes the same share.
  VecX share = VecX::Zero(model.num_nodes());
  for (int e = 0; e < model.num_elements(); ++e)
    for (int a = 0; a < model.nodes_per_element(); ++a)
      share[model.element_nodes(e)[a]] += model.element_rest_volume(e) / model.nodes_per_element();
  EXPECT_LT((mass - kMaterial.density * share).norm(), 1e-12 * mass.norm());
}

// The calls with R_e given (CalcElementRotation, then the ...In calls at the same x) are the
// plain calls bit for bit; and R_e is a rotation whose frame makes the energy rotation invariant.
TYPED_TEST(ElementModelConformanceTest, CallsWithTheRotationGivenAreThePlainCalls) {
  ElementModel& model = *this->model_;
  const VecX x = this->Deform(0.15, TypeParam::kNonAffine);
  ElementVectors plain_f, given_f;
  ElementMatrix plain_K, given_K;
  for (int e = 0; e < model.num_elements(); ++e) {
    const Mat3 R = model.CalcElementRotation(e, x);
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_EQ(model.CalcElementEnergyIn(e, x, R), model.CalcElementEnergy(e, x));
    double plain_fKf = 0.0, given_fKf = 0.0;
    const double plain_U = model.CalcElementForcesAndStiffnessAlong(e, x, plain_f, &plain_fKf);
    const double given_U = model.CalcElementForcesAndStiffnessAlongIn(e, x, R, given_f, &given_fKf);
    EXPECT_EQ(plain_U, given_U);
    EXPECT_EQ(plain_fKf, given_fKf);
    for (int a = 0; a < model.nodes_per_element(); ++a) EXPECT_TRUE(plain_f[a] == given_f[a]);
    model.CalcElementStiffness(e, x, plain_K);
    model.CalcElementStiffnessIn(e, R, given_K);
    EXPECT_TRUE(plain_K == given_K);
  }
  // A different R gives a different energy (the given rotation is used, not recomputed).
  const Mat3 R0 = model.CalcElementRotation(0, x);
  const Mat3 turned = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix() * R0;
  EXPECT_GT(std::abs(model.CalcElementEnergyIn(0, x, turned) - model.CalcElementEnergy(0, x)),
            1e-6 * model.CalcElementEnergy(0, x));
}

}  // namespace
}  // namespace taut
