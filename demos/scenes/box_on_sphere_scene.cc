#include "demos/scenes/box_on_sphere_scene.h"

#include <algorithm>
#include <cmath>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "plugin/hex_shapes.h"

namespace taut {

namespace {
constexpr double kRadius = 0.5;
constexpr double kHalf[3] = {0.2, 0.15, 0.1};  // half sizes of the three boxes [m]
constexpr double kMass[3] = {20.0, 10.0, 5.0};
}  // namespace

BoxOnSphereScene::BoxOnSphereScene(double youngs_modulus, double u_max) {
  holder_.AddStaticGround();
  auto lattice = std::make_shared<HexLattice>(
      MakeSphereHexLattice(kRadius, 0.25, Vec3(0.0, 0.0, kRadius + 0.01)));
  lattice->source = "box_on_sphere sphere";
  DeformableBodySettings settings = MakeSceneBodySettings("sphere", youngs_modulus, 500.0, 1.0);
  settings.contact_margin = 0.05;
  DeformableBody* sphere = world().AddHexBody(lattice, settings);
  if (u_max > 0.0)
    limit_ = world().SetEnergyLimits(sphere, EnergyLimitSettings::PerElementEnergy(u_max));
  // Boxes stacked on the lattice top (its highest nodes), each resting on the one below.
  double top = -HUGE_VAL;
  for (int i = 0; i < sphere->num_nodes(); ++i) top = std::max(top, sphere->node_position(i).z());
  double z = top + 0.002;
  for (int k = 0; k < 3; ++k) {
    boxes_.push_back(
        holder_.AddRigidBody(std::make_unique<btBoxShape>(btVector3(kHalf[k], kHalf[k], kHalf[k])),
                             kMass[k], btVector3(0, 0, z + kHalf[k]), 0.8));
    z += 2.0 * kHalf[k] + 0.002;
  }
}

double BoxOnSphereScene::box_height(int k) const {
  return static_cast<double>(boxes_[k]->getWorldTransform().getOrigin().z());
}

double BoxOnSphereScene::CalcFlattening() const {
  const DeformableBody& body = world().deformable_body(0);
  const VecX& X = body.model().rest_positions();
  double lo = HUGE_VAL, hi = -HUGE_VAL, rest_lo = HUGE_VAL, rest_hi = -HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) {
    lo = std::min(lo, body.node_position(i).z());
    hi = std::max(hi, body.node_position(i).z());
    rest_lo = std::min(rest_lo, X[3 * i + 2]);
    rest_hi = std::max(rest_hi, X[3 * i + 2]);
  }
  return 1.0 - (hi - lo) / (rest_hi - rest_lo);
}

void BoxOnSphereScene::Measure(double /*dt*/) {
  const DeformableBody& sphere = world().deformable_body(0);
  for (int i = 0; i < sphere.num_nodes(); ++i) {
    const Vec3 p = sphere.node_position(i);
    max_penetration_ = std::max(max_penetration_, -p.z());
    const PointContact contact = CalcPointShapeDistance(p, *boxes_[0]->getCollisionShape(),
                                                        boxes_[0]->getWorldTransform(), 0.1);
    if (contact.valid) max_penetration_ = std::max(max_penetration_, -contact.gap);
  }
  for (btRigidBody* box : boxes_) {
    const btVector3 up = box->getWorldTransform().getBasis().getColumn(2);
    max_tilt_ = std::max(max_tilt_, std::acos(std::clamp(static_cast<double>(up.z()), -1.0, 1.0)));
  }
  if (limit_ != nullptr) max_ratio_ = std::max(max_ratio_, limit_->CalcMaxEnergyRatio(sphere.x()));
  max_rigid_rows_ = std::max(max_rigid_rows_, world().last_step_stats().rows_rigid_contact);
}

std::vector<std::string> BoxOnSphereScene::CsvColumns() const {
  return {"box0_z", "box1_z", "box2_z", "flattening", "max_energy_ratio"};
}

void BoxOnSphereScene::AppendCsvValues(std::vector<double>& values) const {
  for (int k = 0; k < 3; ++k) values.push_back(box_height(k));
  values.push_back(CalcFlattening());
  values.push_back(max_ratio_);
}

void BoxOnSphereScene::WriteFigures(nlohmann::json& figures) const {
  figures["box_heights_m"] = {box_height(0), box_height(1), box_height(2)};
  figures["box_gaps_m"] = {box_height(1) - box_height(0) - kHalf[0] - kHalf[1],
                           box_height(2) - box_height(1) - kHalf[1] - kHalf[2]};
  figures["max_box_tilt_deg"] = max_tilt_ * 180.0 / M_PI;
  figures["sphere_flattening"] = CalcFlattening();
  figures["max_penetration_m"] = max_penetration_;
  figures["max_energy_ratio"] = max_ratio_;
  figures["max_rigid_contact_rows"] = max_rigid_rows_;
  figures["coupled_rigid_bodies"] = world().last_step_stats().rigid_bodies_coupled;
}

std::vector<Scene::KeyFrame> BoxOnSphereScene::CollectKeyFrames(int step, int num_steps) {
  return CollectPeakKeyFrames(step, num_steps, CalcFlattening(), &key_flattening_,
                              "largest_flattening", "largest flattening of the sphere");
}

}  // namespace taut
