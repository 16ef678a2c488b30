// The dual path's look-ahead rows (IslandRows::SetLookAheadRows, docs/math.md §5.7 "Rows found
// at the QP step"): limit rows collected at the full QP step v_QP join the QP at v_k linearized
// about v_k, C(x_k) ~ C(x_QP) + h J (v_k - v_QP); only where the kept rows have nothing of their
// group (an element's strain rows), and only limit rows.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "constraints/deformable_island_body.h"
#include "constraints/island_rows.h"
#include "constraints/strain_limit_source.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kLookAheadH = 0.01;

// A soft 2 x 1 x 1-cube tet body after BeginStep, with strain limits that emit every row
// (activation margin +inf) and velocities that stretch it 8 % along x in one step.
struct StretchedBody {
  std::unique_ptr<DeformableBody> body;
  std::unique_ptr<DeformableIslandBody> island_body;
  std::unique_ptr<StrainLimitSource> limits;
  std::vector<IslandBody*> bodies;
  VecX v_stretch;

  StretchedBody() {
    DeformableBodySettings settings;
    settings.name = "bar";
    auto mesh = std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.2, 0.1, 0.1), 2, 1, 1));
    body = std::make_unique<DeformableBody>(
        std::make_unique<TetElementModel>(mesh, settings.material), settings);
    body->BeginStep(kLookAheadH, Vec3::Zero());
    island_body = std::make_unique<DeformableIslandBody>(*body);
    bodies = {island_body.get()};
    StrainLimitSettings strain = StrainLimitSettings::Isotropic(0.95, 1.05);
    strain.activation_margin = HUGE_VAL;
    limits = std::make_unique<StrainLimitSource>(*body, strain, 1);
    // x = x0 + h v with x = diag(1.08, 1, 1) X: every element past its 5 % stretch limit.
    const VecX& X = body->model().rest_positions();
    v_stretch.setZero(X.size());
    for (int i = 0; i < body->num_nodes(); ++i) v_stretch[3 * i] = 0.08 * X[3 * i] / kLookAheadH;
  }
  IslandRows CollectAt(const VecX& v, std::vector<ConstraintSource*> sources) const {
    IslandRows rows;
    rows.Collect(kLookAheadH, bodies, sources, {v}, 1.0);
    return rows;
  }
};

int CountViolated(const IslandRows& rows) {
  int n = 0;
  for (const ConstraintRow& row : rows.rows()) n += row.violation() > 0.0 ? 1 : 0;
  return n;
}

// The largest |C_shifted - C(x_k)| over the rows when v_QP is a distance `step` from v_k.
double CalcLinearizationError(const StretchedBody& bar, const VecX& v_k, const VecX& direction,
                              double step) {
  const VecX v_qp = v_k + step * direction;
  const IslandRows at_qp = bar.CollectAt(v_qp, {bar.limits.get()});
  const IslandRows at_k = bar.CollectAt(v_k, {bar.limits.get()});
  IslandRows look_ahead = bar.CollectAt(v_k, {});  // no kept rows
  const int added = look_ahead.SetLookAheadRows(at_qp, 0, {}, kLookAheadH, {v_k}, {v_qp});
  EXPECT_EQ(added, CountViolated(at_qp));  // none kept: every violated row joins
  double worst = 0.0;
  for (int c = 0; c < look_ahead.size(); ++c)
    for (int d = 0; d < at_k.size(); ++d)
      if (at_k[d].key == look_ahead[c].key)
        worst = std::max(worst, std::abs(look_ahead[c].C - at_k[d].C));
  return worst;
}

TEST(LookAheadRowsTest, ShiftedRowIsTheFirstOrderValueAtTheIterate) {
  StretchedBody bar;
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  VecX direction(bar.v_stretch.size());
  for (int i = 0; i < direction.size(); ++i) direction[i] = normal(rng);
  // |h dv| <= 0.5 mm on 0.1 m cells: 0.5 % strain, the stretches stay well apart.
  direction *= 5e-4 / (kLookAheadH * direction.cwiseAbs().maxCoeff());
  const double coarse = CalcLinearizationError(bar, bar.v_stretch, direction, 1.0);
  const double fine = CalcLinearizationError(bar, bar.v_stretch, direction, 0.5);
  std::printf("look-ahead C error: %.3e at the full distance, %.3e at half (ratio %.2f)\n", coarse,
              fine, coarse / fine);
  EXPECT_GT(coarse, 0.0);
  // Second order: half the distance, a quarter of the error (3.4-4.6 allows the third order).
  EXPECT_GT(coarse / fine, 3.4);
  EXPECT_LT(coarse / fine, 4.6);
}

TEST(LookAheadRowsTest, OnlyElementsWithoutKeptRowsJoinAndKeptRowsStay) {
  StretchedBody bar;
  const IslandRows at_qp = bar.CollectAt(bar.v_stretch, {bar.limits.get()});
  ASSERT_GT(at_qp.size(), 0);
  // Kept: the rows of element 0 only (a source that emits them).
  class ElementZeroRows final : public ConstraintSource {
   public:
    explicit ElementZeroRows(const IslandRows& from) : from_(from) {}
    int AppendIslandRows(const IslandIterate& /*iterate*/,
                         std::vector<ConstraintRow>& rows) override {
      int n = 0;
      for (const ConstraintRow& row : from_.rows())
        if (row.element == 0) {
          rows.push_back(row);
          rows.back().key ^= 1ull << 1;  // another principal direction: a sibling key
          ++n;
        }
      return n;
    }
    double CalcIslandViolationSum(const IslandIterate& /*iterate*/) const override { return 0.0; }

   private:
    const IslandRows& from_;
  } element_zero(at_qp);
  const VecX v_k = VecX::Zero(bar.v_stretch.size());
  IslandRows rows = bar.CollectAt(v_k, {&element_zero});
  const int kept = rows.size();
  ASSERT_GT(kept, 0);
  const int added = rows.SetLookAheadRows(at_qp, kept, {}, kLookAheadH, {v_k}, {bar.v_stretch});
  int expected = 0;
  for (const ConstraintRow& row : at_qp.rows())
    expected += row.element != 0 && row.violation() > 0.0 ? 1 : 0;
  EXPECT_EQ(added, expected);
  for (int c = 0; c < kept; ++c) EXPECT_EQ(rows[c].element, 0);
  for (int c = kept; c < rows.size(); ++c) EXPECT_NE(rows[c].element, 0);
  // Each body lists its rows: the kept and the added ones, once each.
  EXPECT_EQ(static_cast<int>(rows.body_rows(0).size()), rows.size());
  // A second call at a v_QP that violates nothing (4 % stretch) keeps only the sticky rows.
  const VecX v_inside = 0.5 * bar.v_stretch;
  const IslandRows at_inside = bar.CollectAt(v_inside, {bar.limits.get()});
  ASSERT_EQ(CountViolated(at_inside), 0);
  std::vector<std::uint64_t> sticky{rows[kept].key};
  EXPECT_EQ(rows.SetLookAheadRows(at_inside, kept, sticky, kLookAheadH, {v_k}, {v_inside}), 1);
  EXPECT_EQ(rows[kept].key, sticky[0]);
  EXPECT_EQ(static_cast<int>(rows.body_rows(0).size()), kept + 1);
}

}  // namespace
}  // namespace taut
