// The limit rows' least-squares multipliers (constraints/limit_multiplier_refit.h) and the
// certificate that uses them (CalcKktResidualsWithRefit, docs/math.md §5.10): with redundant rows
// the force may sit on a row short of its bound while another row at its bound could carry it;
// the certificate then holds for the refitted multipliers. A slack row that alone holds the body
// is not released into a certificate. Friction forces just outside their Coulomb disks (an
// augmented-Lagrangian update projects onto the disk of the previous normal multiplier) are
// certified projected onto the current disks when that keeps the step stationary.
#include "constraints/limit_multiplier_refit.h"

#include <gtest/gtest.h>

#include <random>

#include "constraints/kkt_certificate.h"

namespace taut {
namespace {

constexpr double kRefitH = 0.01;
constexpr double kRefitTolerance = 1e-3;

// Point masses (one 3-vector block each, A = m I) with a target velocity v*.
class RefitPointMasses final : public IslandBody {
 public:
  RefitPointMasses(int n, double mass) : mass_(mass), v_star_(VecX::Zero(3 * n)), v_(v_star_) {}
  void set_v_star(const VecX& v_star) { v_star_ = v_star; }
  int num_blocks() const override { return static_cast<int>(v_.size() / 3); }
  const VecX& v_star() const override { return v_star_; }
  const VecX& v() const override { return v_; }
  void set_v(const VecX& v) override { v_ = v; }
  void SolveSystemColumns(Eigen::Ref<MatX> columns) const override { columns /= mass_; }
  void ApplySystemMatrix(const VecX& v, VecX& out) const override { out = mass_ * v; }
  bool is_free_block(int) const override { return true; }
  void CalcPositions(double h, const VecX& v, VecX& x) const override { x = h * v; }
  double CalcBlockMobility(int, const Vec3& J) const override { return J.squaredNorm() / mass_; }
  void ResetNewtonMatrix() override {}
  bool IsInNewtonPattern(int, int) const override { return true; }
  void AddNewtonBlock(int, int, const Mat3&) override {}
  void FactorNewtonMatrix() override {}
  void SolveNewton(Eigen::Ref<VecX> rhs) const override { rhs /= mass_; }
  void ApplyNewtonMatrix(const VecX& v, VecX& out) const override { out = mass_ * v; }

 private:
  double mass_;
  VecX v_star_, v_;
};

// Unilateral limit rows with given C and one Jacobian entry per block.
struct RefitGivenRow {
  double C;
  std::vector<std::pair<int, Vec3>> entries;  // (block, J)
};

class RefitGivenRows final : public ConstraintSource {
 public:
  explicit RefitGivenRows(std::vector<RefitGivenRow> rows) : rows_(std::move(rows)) {}
  int AppendIslandRows(const IslandIterate&, std::vector<ConstraintRow>& rows) override {
    for (size_t r = 0; r < rows_.size(); ++r) {
      ConstraintRow& row = rows.emplace_back();
      row.type = RowType::kStrainLimit;
      row.key = r;
      row.C = rows_[r].C;
      row.body = 0;
      row.num_nodes = static_cast<int>(rows_[r].entries.size());
      for (int n = 0; n < row.num_nodes; ++n) {
        row.nodes[n] = rows_[r].entries[n].first;
        row.J[n] = rows_[r].entries[n].second;
      }
    }
    return static_cast<int>(rows_.size());
  }
  double CalcIslandViolationSum(const IslandIterate&) const override { return 0.0; }

 private:
  std::vector<RefitGivenRow> rows_;
};

struct RefitIsland {
  RefitPointMasses body;
  RefitGivenRows source;
  std::vector<IslandBody*> bodies{&body};
  IslandRows rows;
  std::vector<VecX> v;
  RefitIsland(int n, double mass, std::vector<RefitGivenRow> given)
      : body(n, mass), source(std::move(given)) {
    v = {VecX::Zero(3 * n)};
    std::vector<ConstraintSource*> sources{&source};
    rows.Collect(kRefitH, bodies, sources, v, 1.0);
  }
  KktResiduals Residuals(const VecX& lambda) {
    VecX scratch;
    return CalcKktResiduals(bodies, rows, lambda, v, kRefitH, 1.0, scratch);
  }
  KktResiduals ResidualsWithRefit(const VecX& lambda, VecX& certified) {
    std::vector<VecX> a_dv;
    return CalcKktResidualsWithRefit(bodies, rows, lambda, v, kRefitH, 1.0, kRefitTolerance, 1e-2,
                                     a_dv, certified);
  }
};

// One frictional contact of a point mass on the ground z = 0 (rows n = +z, t1 = +x, t2 = +y).
class RefitGroundContact final : public ConstraintSource {
 public:
  explicit RefitGroundContact(double mu) : mu_(mu) {}
  int AppendIslandRows(const IslandIterate&, std::vector<ConstraintRow>& rows) override {
    const Vec3 directions[3] = {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    for (int r = 0; r < 3; ++r) {
      ConstraintRow& row = rows.emplace_back();
      row.type = RowType::kContact;
      row.key = r;
      row.C = 0.0;
      row.friction_of = r;
      row.mu = r > 0 ? mu_ : 0.0;
      row.body = 0;
      row.num_nodes = 1;
      row.nodes[0] = 0;
      row.J[0] = directions[r];
    }
    return 3;
  }
  double CalcIslandViolationSum(const IslandIterate&) const override { return 0.0; }

 private:
  double mu_;
};

// A (v - v*) per body of an island at its v: the refit's momentum side.
std::vector<VecX> MomentumAt(const RefitIsland& island) {
  std::vector<VecX> a_dv;
  CalcVelocityChangeMomentum(island.bodies, island.v, a_dv);
  return a_dv;
}

// A 1 kg mass sticking on the ground (v = 0) with v* = (-0.5, 0, -1): A (v - v*) = (0.5, 0, 1)
// is held by lambda_n = 1 and friction (0.5, 0), on the rim of the mu = 0.5 disk.
struct RefitContactIsland {
  RefitPointMasses body{1, 1.0};
  RefitGroundContact source{0.5};
  std::vector<IslandBody*> bodies{&body};
  IslandRows rows;
  std::vector<VecX> v{VecX::Zero(3)};
  RefitContactIsland() {
    body.set_v_star(Vec3(-0.5, 0, -1));
    std::vector<ConstraintSource*> sources{&source};
    rows.Collect(kRefitH, bodies, sources, v, 1.0);
  }
  KktResiduals ResidualsWithRefit(const VecX& lambda, VecX& certified) {
    std::vector<VecX> a_dv;
    return CalcKktResidualsWithRefit(bodies, rows, lambda, v, kRefitH, 1.0, kRefitTolerance, 1e-2,
                                     a_dv, certified);
  }
};

// The certificate computes A (v - v*) once and shares it among the multipliers it tries; the
// residuals from the shared product are bitwise those of a product per call, and the product it
// hands back is A (v - v*) at v.
TEST(LimitMultiplierRefitTest, SharedMomentumGivesTheResidualsOfAProductPerCall) {
  RefitContactIsland island;
  island.v[0] = Vec3(0.2, -0.1, 0.3);
  const VecX lambda = (VecX(3) << 1.0, 0.3, -0.2).finished();
  VecX scratch;
  const KktResiduals per_call =
      CalcKktResiduals(island.bodies, island.rows, lambda, island.v, kRefitH, 1.0, scratch);
  std::vector<VecX> a_dv;
  CalcVelocityChangeMomentum(island.bodies, island.v, a_dv);
  const KktResiduals shared =
      CalcKktResiduals(island.bodies, island.rows, lambda, island.v, kRefitH, 1.0, a_dv);
  EXPECT_EQ(shared.stationarity, per_call.stationarity);
  EXPECT_GT(shared.stationarity, 0.0);
  EXPECT_EQ(shared.primal, per_call.primal);
  EXPECT_EQ(shared.complementarity, per_call.complementarity);
  EXPECT_EQ(shared.dual, per_call.dual);
  // A = M for this particle: A (v - v*) = m (v - v*).
  std::vector<VecX> handed_back;
  VecX certified;
  CalcKktResidualsWithRefit(island.bodies, island.rows, lambda, island.v, kRefitH, 1.0,
                            kRefitTolerance, 1e-2, handed_back, certified);
  ASSERT_EQ(handed_back.size(), 1u);
  VecX expected;
  island.bodies[0]->ApplySystemMatrix(island.v[0] - island.body.v_star(), expected);
  EXPECT_EQ(handed_back[0], expected);
}

// Friction 2e-5 outside the disk (dual residual 2e-5 > 1e-6): projected onto the disk it is the
// exact force, certified; sliding with the force it is not.
TEST(LimitMultiplierRefitTest, FrictionJustOutsideItsDiskIsCertifiedOnTheDisk) {
  RefitContactIsland island;
  const VecX lambda = (VecX(3) << 1.0, 0.50002, 0.0).finished();
  VecX scratch;
  const KktResiduals plain =
      CalcKktResiduals(island.bodies, island.rows, lambda, island.v, kRefitH, 1.0, scratch);
  EXPECT_NEAR(plain.dual, 2e-5, 1e-12);
  EXPECT_FALSE(IsCertified(plain, kRefitTolerance, 1e-2));
  VecX certified;
  const KktResiduals kkt = island.ResidualsWithRefit(lambda, certified);
  EXPECT_TRUE(IsCertified(kkt, kRefitTolerance, 1e-2));
  EXPECT_LE(kkt.dual, 1e-15);
  EXPECT_NEAR(certified[1], 0.5, 1e-15);  // on the rim mu lambda_n
  EXPECT_EQ(certified[0], 1.0);
  EXPECT_LT(kkt.stationarity, 1e-12);

  // Sliding along +x, with the force: not Coulomb on the rim, so not moved there.
  island.v[0] = Vec3(1.0, 0, 0);
  island.body.set_v_star(Vec3(0.5, 0, -1));
  const KktResiduals along = island.ResidualsWithRefit(lambda, certified);
  EXPECT_FALSE(IsCertified(along, kRefitTolerance, 1e-2));
  EXPECT_EQ(certified, lambda);
}

// Friction far outside the disk (0.8 against 0.5): on the disk it leaves 0.3 of the force
// unbalanced, so nothing is certified and the solver's multipliers stay.
TEST(LimitMultiplierRefitTest, FrictionFarOutsideItsDiskIsNotProjectedIntoACertificate) {
  RefitContactIsland island;
  island.body.set_v_star(Vec3(-0.8, 0, -1));
  const VecX lambda = (VecX(3) << 1.0, 0.8, 0.0).finished();
  VecX certified;
  const KktResiduals kkt = island.ResidualsWithRefit(lambda, certified);
  EXPECT_FALSE(IsCertified(kkt, kRefitTolerance, 1e-2));
  EXPECT_EQ(certified, lambda);
  EXPECT_NEAR(kkt.dual, 0.3 / 1.0, 1e-12);
}

// The mass sliding along -x at 1 m/s (v* = (-1.5, 0, -1), so A (v - v*) = (0.5, 0, 1)) with
// friction 1e-4 short of the rim: inside the disk yet sliding fails complementarity; on the rim,
// opposing the slip, the same force is Coulomb's and is certified. Friction pushing along the slip
// is not moved onto the rim.
TEST(LimitMultiplierRefitTest, FrictionJustInsideItsDiskWhileSlidingIsCertifiedOnTheRim) {
  RefitContactIsland island;
  island.body.set_v_star(Vec3(-1.5, 0, -1));
  island.v[0] = Vec3(-1.0, 0, 0);
  const VecX lambda = (VecX(3) << 1.0, 0.4999, 0.0).finished();
  VecX scratch;
  const KktResiduals plain =
      CalcKktResiduals(island.bodies, island.rows, lambda, island.v, kRefitH, 1.0, scratch);
  EXPECT_NEAR(plain.max_complementarity(), kRefitH * 1.0, 1e-15);
  EXPECT_FALSE(IsCertified(plain, kRefitTolerance, 1e-2));
  VecX certified;
  const KktResiduals kkt = island.ResidualsWithRefit(lambda, certified);
  EXPECT_TRUE(IsCertified(kkt, kRefitTolerance, 1e-2));
  EXPECT_EQ(kkt.max_complementarity(), 0.0);
  EXPECT_NEAR(certified[1], 0.5, 1e-15);

  island.v[0] = Vec3(1.0, 0, 0);  // sliding along +x, with the force
  island.body.set_v_star(Vec3(0.5, 0, -1));
  const KktResiduals along = island.ResidualsWithRefit(lambda, certified);
  EXPECT_FALSE(IsCertified(along, kRefitTolerance, 1e-2));
  EXPECT_EQ(certified, lambda);
}

// A 2 kg mass at rest (v = 0) whose target velocity v* = (0, 0, -1) is held by two rows along +z:
// row 0 at its bound (C = 0), row 1 short of it (C = 5e-3). The force A (v - v*) = (0, 0, 2)
// split 30/70 (what an augmented-Lagrangian iterate may carry) violates complementarity on row 1.
TEST(LimitMultiplierRefitTest, ForceOnARowShortOfItsBoundMovesToTheRowAtItsBound) {
  RefitIsland island(1, 2.0, {{0.0, {{0, Vec3(0, 0, 1)}}}, {5e-3, {{0, Vec3(0, 0, 1)}}}});
  island.body.set_v_star(Vec3(0, 0, -1));
  const VecX split = (VecX(2) << 0.6, 1.4).finished();
  const KktResiduals first = island.Residuals(split);
  EXPECT_LT(first.stationarity, 1e-12);
  EXPECT_NEAR(first.max_complementarity(), 5e-3, 1e-15);
  EXPECT_FALSE(IsCertified(first, kRefitTolerance, 1e-2));

  VecX fit = split;
  RefitLimitMultipliers(island.bodies, island.rows, MomentumAt(island), kRefitTolerance, 0.0, 100,
                        fit);
  EXPECT_EQ(fit[1], 0.0);           // released: C > tolerance
  EXPECT_NEAR(fit[0], 2.0, 1e-12);  // the whole force on the row at its bound
  VecX certified;
  const KktResiduals refit = island.ResidualsWithRefit(split, certified);
  EXPECT_TRUE(IsCertified(refit, kRefitTolerance, 1e-2));
  EXPECT_EQ(refit.max_complementarity(), 0.0);
  EXPECT_EQ(certified, fit);  // the multipliers that passed, for the solver to report
}

// The same mass held only by the slack row along +z; the row at its bound points along +x and
// cannot carry the force. Releasing the slack row leaves A (v - v*) unbalanced: v is not a KKT
// point and the certificate keeps failing with the first residuals.
TEST(LimitMultiplierRefitTest, ASlackRowThatAloneHoldsTheBodyIsNotReleasedIntoACertificate) {
  RefitIsland island(1, 2.0, {{0.0, {{0, Vec3(1, 0, 0)}}}, {5e-3, {{0, Vec3(0, 0, 1)}}}});
  island.body.set_v_star(Vec3(0, 0, -1));
  const VecX lambda = (VecX(2) << 0.0, 2.0).finished();
  VecX certified;
  const KktResiduals refit = island.ResidualsWithRefit(lambda, certified);
  EXPECT_FALSE(IsCertified(refit, kRefitTolerance, 1e-2));
  EXPECT_EQ(certified, lambda);  // nothing passed: the solver's own multipliers stay
  EXPECT_NEAR(refit.max_complementarity(), 5e-3, 1e-15);
  EXPECT_LT(refit.stationarity, 1e-12);

  VecX fit = lambda;
  RefitLimitMultipliers(island.bodies, island.rows, MomentumAt(island), kRefitTolerance, 0.0, 100,
                        fit);
  EXPECT_EQ(fit[1], 0.0);
  EXPECT_EQ(fit[0], 0.0);  // +x cannot push against -z: the projection keeps it at 0
}

// Random redundant rows (12 rows on 2 masses, 6 DOFs): the refit is the nonnegative least-squares
// solution, checked by its optimality conditions: with r = A (v - v*) - J^T lambda, J_c . r = 0
// on rows that push and <= 0 on active rows at 0; slack rows are released.
TEST(LimitMultiplierRefitTest, RefitSatisfiesTheNonnegativeLeastSquaresOptimality) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<RefitGivenRow> given;
  for (int r = 0; r < 12; ++r) {
    const double C = r % 3 == 0 ? 4e-3 : 0.5 * kRefitTolerance * unit(rng);
    given.push_back(
        {C,
         {{0, Vec3(unit(rng), unit(rng), unit(rng))}, {1, Vec3(unit(rng), unit(rng), unit(rng))}}});
  }
  RefitIsland island(2, 1.5, given);
  island.body.set_v_star((VecX(6) << 0.3, -0.2, -1.0, 0.1, 0.4, -0.7).finished());
  VecX fit = VecX::Constant(12, 0.5);
  RefitLimitMultipliers(island.bodies, island.rows, MomentumAt(island), kRefitTolerance, 0.0,
                        100000, fit);

  VecX r = 1.5 * (island.v[0] - island.body.v_star());
  for (int c = 0; c < 12; ++c)
    island.rows[c].ForEachEntry(
        [&](int, int block, const Vec3& J) { r.segment<3>(3 * block) -= fit[c] * J; });
  const double scale = (1.5 * island.body.v_star()).norm();
  for (int c = 0; c < 12; ++c) {
    double jr = 0.0;
    island.rows[c].ForEachEntry(
        [&](int, int block, const Vec3& J) { jr += J.dot(r.segment<3>(3 * block)); });
    EXPECT_GE(fit[c], 0.0) << "row " << c;
    if (island.rows[c].C > kRefitTolerance) {
      EXPECT_EQ(fit[c], 0.0) << "slack row " << c;
    } else if (fit[c] > 0.0) {
      EXPECT_NEAR(jr, 0.0, 1e-8 * scale) << "pushing row " << c;
    } else {
      EXPECT_LE(jr, 1e-8 * scale) << "active row at 0, " << c;
    }
  }
}

}  // namespace
}  // namespace taut
