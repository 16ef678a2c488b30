#include "demos/scenes/vertical_beam_scene.h"

#include "plugin/box_tet_mesher.h"

namespace taut {

namespace {
constexpr double kWidth = 0.2;
constexpr double kHeight = 1.0;
}  // namespace

std::vector<StrainProjection> VerticalBeamScene::AllModes() {
  return {StrainProjection::kHyperbolic, StrainProjection::kEllipsoid,
          StrainProjection::kOrthogonal, StrainProjection::kLinearInterpolation};
}

VerticalBeamScene::VerticalBeamScene(const std::vector<StrainProjection>& modes, int cells_xy,
                                     int cells_z)
    : modes_(modes) {
  for (size_t c = 0; c < modes.size(); ++c) {
    const Vec3 corner(0.6 * static_cast<double>(c), 0.0, 0.0);
    auto mesh = std::make_shared<TetMesh>(
        MakeBoxTetMesh(Vec3(kWidth, kWidth, kHeight), cells_xy, cells_xy, cells_z, corner));
    const DeformableBodySettings settings = MakeSceneBodySettings(
        std::string("column_") + GetStrainProjectionName(modes[c]), 10e3, 1000.0, 1.0);
    mesh->source = settings.name;
    DeformableBody* body = world().AddTetBody(mesh, settings);
    body->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
    // Transverse axis x limited to 0.95..1.05; y and the vertical axis z free.
    const double free = kUnlimitedStretch;
    limits_.push_back(world().SetStrainLimits(
        body,
        StrainLimitSettings::PerAxis(Vec3(0.95, 0.0, 0.0), Vec3(1.05, free, free), modes[c])));
    std::vector<int> top;
    for (int i = 0; i < body->num_nodes(); ++i)
      if (mesh->nodes[i].z() > kHeight - 1e-9) top.push_back(i);
    top_nodes_.push_back(top);
  }
  first_violation_.assign(modes.size(), -1);
  max_strain_.assign(modes.size(), 0.0);
  max_rows_.assign(modes.size(), 0);
  max_violation_after_.assign(modes.size(), 0.0);
}

double VerticalBeamScene::CalcLimitedAxisStrain(int c) const {
  return limits_[c]->CalcMaxAxisStrain(world().deformable_body(c).x(), 0);
}

double VerticalBeamScene::CalcTopHeight(int c) const {
  const DeformableBody& body = world().deformable_body(c);
  double z = 0.0;
  for (int i : top_nodes_[c]) z += body.node_position(i).z();
  return z / static_cast<double>(top_nodes_[c].size());
}

void VerticalBeamScene::Measure(double dt) {
  ++step_;
  for (size_t c = 0; c < modes_.size(); ++c) {
    const double violation = limits_[c]->CalcMaxViolation(world().deformable_body(c).x0() +
                                                          dt * world().deformable_body(c).v_star());
    if (first_violation_[c] < 0 && violation > 0.0) first_violation_[c] = step_;
    max_strain_[c] = std::max(max_strain_[c], CalcLimitedAxisStrain(static_cast<int>(c)));
    max_violation_after_[c] = std::max(
        max_violation_after_[c], limits_[c]->CalcMaxViolation(world().deformable_body(c).x()));
  }
}

std::vector<std::string> VerticalBeamScene::CsvColumns() const {
  std::vector<std::string> columns;
  for (StrainProjection mode : modes_) {
    columns.push_back(std::string("x_strain_") + GetStrainProjectionName(mode));
    columns.push_back(std::string("top_height_m_") + GetStrainProjectionName(mode));
  }
  return columns;
}

void VerticalBeamScene::AppendCsvValues(std::vector<double>& values) const {
  for (size_t c = 0; c < modes_.size(); ++c) {
    values.push_back(CalcLimitedAxisStrain(static_cast<int>(c)));
    values.push_back(CalcTopHeight(static_cast<int>(c)));
  }
}

void VerticalBeamScene::WriteFigures(nlohmann::json& figures) const {
  for (size_t c = 0; c < modes_.size(); ++c) {
    nlohmann::json& entry = figures["modes"][GetStrainProjectionName(modes_[c])];
    entry["first_violation_step"] = first_violation_[c];
    entry["max_limited_axis_strain"] = max_strain_[c];
    entry["final_limited_axis_strain"] = CalcLimitedAxisStrain(static_cast<int>(c));
    entry["max_violation_after_solve"] = max_violation_after_[c];
    entry["top_height_m"] = CalcTopHeight(static_cast<int>(c));
  }
  figures["limit"] = "0.95 <= s <= 1.05 along x";
}

std::vector<Scene::KeyFrame> VerticalBeamScene::CollectKeyFrames(int step, int num_steps) {
  std::vector<KeyFrame> frames;
  if (step == 0) frames.push_back({"start", "start"});
  // The columns are identical until a limit first binds, so their first violations coincide
  // unless the modes differ before it: one frame per distinct step.
  std::string modes;
  for (size_t c = 0; c < modes_.size(); ++c)
    if (step > 0 && first_violation_[c] == step)
      modes += (modes.empty() ? "" : ", ") + std::string(GetStrainProjectionName(modes_[c]));
  if (!modes.empty())
    frames.push_back({"first_violation_step" + std::to_string(step), "first violation: " + modes});
  if (step == num_steps && step > 0) frames.push_back({"end", "end"});
  return frames;
}

}  // namespace taut
