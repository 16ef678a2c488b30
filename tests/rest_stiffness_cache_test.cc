// The rest stiffness the element models store at construction: bitwise the K0 a fresh
// computation gives, per material, and what the stiffness assembly uses.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "plugin/box_tet_mesher.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"
#include "plugin/tet_element_traits.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

const Material kSoft{1e5, 0.3, 1000};
const Material kStiff{4e6, 0.45, 1000};

// A 2 x 2 x 1 box of 6-tet cubes with every node moved by up to 5 % of a cell (no tet inverts).
std::shared_ptr<const TetMesh> MakeDistortedBoxTetMesh() {
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(0.2, 0.2, 0.1), 2, 2, 1));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> shift(-0.005, 0.005);
  for (Vec3& X : mesh->nodes) X += Vec3(shift(rng), shift(rng), shift(rng));
  mesh->source = "distorted box";
  return mesh;
}

// Positions x = R X + small random displacement, so every element has its own rotation.
VecX MakeDeformedPositions(const VecX& X, std::mt19937& rng) {
  const Mat3 R = testing::RandomRotation(rng);
  std::uniform_real_distribution<double> shift(-0.002, 0.002);
  VecX x(X.size());
  for (Eigen::Index i = 0; i < X.size() / 3; ++i)
    x.segment<3>(3 * i) = R * X.segment<3>(3 * i) + Vec3(shift(rng), shift(rng), shift(rng));
  return x;
}

TEST(RestStiffnessCacheTest, TetBlocksEqualFreshBlocksBitwise) {
  const TetElementModel model(MakeDistortedBoxTetMesh(), kSoft);
  for (int e = 0; e < model.num_elements(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        EXPECT_EQ(model.rest_stiffness_block(e, a, b),
                  CalcRestStiffnessBlock(model.rest().elements[e], model.lame(), a, b))
            << "element " << e << " block (" << a << ", " << b << ")";
}

TEST(RestStiffnessCacheTest, TetBlocksFollowTheMaterial) {
  const auto mesh = MakeDistortedBoxTetMesh();
  const TetElementModel soft(mesh, kSoft), stiff(mesh, kStiff);
  for (int e = 0; e < soft.num_elements(); ++e) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        EXPECT_NE(soft.rest_stiffness_block(e, a, b), stiff.rest_stiffness_block(e, a, b));
        EXPECT_EQ(stiff.rest_stiffness_block(e, a, b),
                  CalcRestStiffnessBlock(stiff.rest().elements[e], stiff.lame(), a, b));
      }
    }
  }
}

TEST(RestStiffnessCacheTest, TetAssemblyEqualsTheRotatedClosedFormBitwise) {
  // One element per call with an identity index map: values = 0 + the closed form's blocks of
  // scale R K0 R^T exactly (CalcRotatedTetStiffnessBlocks), which are the fresh rotated rest
  // blocks to round-off.
  const auto mesh = MakeDistortedBoxTetMesh();
  TetElementModel model(mesh, kStiff);
  std::mt19937 rng(3);
  const VecX x = MakeDeformedPositions(model.rest_positions(), rng);
  VecX f = VecX::Zero(x.size());
  model.UpdateRotationsAndAddForces(x, f);
  const double scale = 0.37;
  std::vector<int> index_map(144 * model.num_elements(), -1);
  for (int e = 0; e < model.num_elements(); ++e) {
    std::fill(index_map.begin(), index_map.end(), -1);
    for (int k = 0; k < 144; ++k) index_map[144 * e + k] = k;
    std::vector<double> values(144, 0.0);
    model.AddScaledStiffness(scale, index_map, values.data());
    const Mat3& R = model.rotation(e);
    TetRestStiffness blocks;
    CalcRotatedTetStiffnessBlocks(model.rest().elements[e], model.lame(), R, scale, blocks);
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const Eigen::Map<const Mat3> assembled(values.data() + 9 * (4 * a + b));
        EXPECT_EQ(assembled, blocks[4 * a + b])
            << "element " << e << " block (" << a << ", " << b << ")";
        const Mat3 fresh =
            scale * (R * CalcRestStiffnessBlock(model.rest().elements[e], model.lame(), a, b) *
                     R.transpose());
        EXPECT_LE((assembled - fresh).norm(), 1e-13 * fresh.norm() + 1e-9)
            << "element " << e << " block (" << a << ", " << b << ")";
      }
    }
  }
}

TEST(RestStiffnessCacheTest, HexStiffnessEqualsFreshAndFollowsTheMaterial) {
  auto lattice =
      std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(0.2, 0.1, 0.1), 2, 1, 1, Vec3::Zero()));
  lattice->source = "box lattice";
  const HexElementModel soft(lattice, kSoft), stiff(lattice, kStiff);
  for (int e = 0; e < soft.num_elements(); ++e) {
    const HexNodes X = soft.GatherElement(soft.rest_positions(), e);
    // Equal cells share one K_e (ShareEqualHexStiffnesses): a fresh one's to its tolerance.
    for (const HexElementModel* model : {&soft, &stiff}) {
      const Mat24 fresh = CalcHexRestElement(X, model->lame()).stiffness();
      EXPECT_LE((model->rest(e).stiffness() - fresh).cwiseAbs().maxCoeff(),
                kSharedHexStiffnessTolerance * fresh.cwiseAbs().maxCoeff())
          << "element " << e;
    }
    EXPECT_NE(soft.rest(e).stiffness(), stiff.rest(e).stiffness());
  }
}

}  // namespace
}  // namespace taut
