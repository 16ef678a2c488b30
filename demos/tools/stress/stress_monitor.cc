#include "demos/tools/stress/stress_monitor.h"

#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace taut::stress {

StressMonitor::StressMonitor(const DeformableWorld& world, double ground_z)
    : world_(world), ground_z_(ground_z) {
  initial_energy_ = CalcTotalEnergy();
  max_energy_ = initial_energy_;
  final_energy_ = initial_energy_;
  max_penetration_ = std::max(0.0, -CalcLowestGap());
}

double StressMonitor::CalcTotalEnergy() const {
  const btVector3 g = world_.getGravity();
  const Vec3 gravity(g.x(), g.y(), g.z());
  const Vec3 ground_point(0.0, 0.0, ground_z_);
  double energy = 0.0;
  // Deformables: kinetic + elastic + potential -m_i g . (x_i - ground).
  for (int b = 0; b < world_.num_deformable_bodies(); ++b) {
    const DeformableBody& body = world_.deformable_body(b);
    energy += body.CalcKineticEnergy() + body.CalcElasticEnergy();
    for (int i = 0; i < body.num_nodes(); ++i)
      energy -= body.mass()[i] * gravity.dot(body.node_position(i) - ground_point);
  }
  // Dynamic rigid bodies: translational + rotational kinetic + potential of the centre of mass.
  const btCollisionObjectArray& objects = world_.getCollisionObjectArray();
  for (int o = 0; o < objects.size(); ++o) {
    const btRigidBody* rigid = btRigidBody::upcast(objects[o]);
    if (rigid == nullptr || rigid->getInvMass() == 0.0) continue;
    const double m = 1.0 / rigid->getInvMass();
    const btVector3 w = rigid->getAngularVelocity();
    const btVector3 w_local = rigid->getWorldTransform().getBasis().transpose() * w;
    const btVector3 inertia = rigid->getLocalInertia();
    const btVector3 p = rigid->getCenterOfMassPosition();
    energy += 0.5 * m * rigid->getLinearVelocity().length2() +
              0.5 * (inertia * w_local).dot(w_local) -
              m * gravity.dot(Vec3(p.x(), p.y(), p.z()) - ground_point);
  }
  return energy;
}

double StressMonitor::CalcLowestGap() const {
  double lowest = HUGE_VAL;
  for (int b = 0; b < world_.num_deformable_bodies(); ++b) {
    const DeformableBody& body = world_.deformable_body(b);
    for (int i = 0; i < body.num_nodes(); ++i) lowest = std::min(lowest, body.node_position(i).z());
  }
  return lowest - ground_z_;
}

bool StressMonitor::IsStateFinite() const {
  for (int b = 0; b < world_.num_deformable_bodies(); ++b) {
    const DeformableBody& body = world_.deformable_body(b);
    if (!body.x().allFinite() || !body.v().allFinite()) return false;
  }
  return true;
}

void StressMonitor::Record() {
  final_energy_ = CalcTotalEnergy();
  // A NaN energy must show up as growth, so compare with !(<=).
  if (!(final_energy_ <= max_energy_)) max_energy_ = final_energy_;
  const StepStats& stats = world_.last_step_stats();
  max_violation_ = std::max(max_violation_, stats.violation_after);
  if (!stats.converged) ++unconverged_steps_;
  max_penetration_ = std::max(max_penetration_, -CalcLowestGap());
}

void StressMonitor::Run(DeformableWorld& world, double h, int steps, CellResult& result,
                        const std::function<void(int)>& after_step) {
  for (int step = 0; step < steps; ++step) {
    try {
      world.stepSimulation(h, 1, h);
    } catch (const SimulationError& e) {
      throw SimulationError("step " + std::to_string(step + 1) + ": " + e.what());
    } catch (const InputError& e) {
      throw InputError("step " + std::to_string(step + 1) + ": " + e.what());
    }
    result.steps_run = step + 1;
    if (!IsStateFinite()) {
      result.finite = false;
      return;
    }
    Record();
    if (after_step) after_step(step);
  }
}

double StressMonitor::CalcEnergyGrowth() const {
  const double growth = max_energy_ - initial_energy_;
  if (growth <= 0.0) return 0.0;
  return growth / std::max(std::abs(initial_energy_), 1e-300);
}

void StressMonitor::AddStandardChecks(CellResult& result,
                                      const StandardTolerances& tolerances) const {
  result.AddCheck("energy growth", CalcEnergyGrowth(), tolerances.energy_growth);
  result.AddCheck("violation", max_violation_, tolerances.violation);
  result.AddCheck("penetration [m]", max_penetration_, tolerances.penetration);
  result.AddFigure("unconverged steps", unconverged_steps_);
}

}  // namespace taut::stress
