// Emitters of liquid (docs/fluids.md, "Emitters"): an emitter's particles wait parked (inverse
// mass 0, far below its nozzle, scene_fluid.cpp) and leave it in layers at the start of the step
// they are due in, placed where a particle that left at its layer's time would be by then.
#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "motes/simulation.h"
#include "shared/neighbours.h"

namespace motes {

using shared::vec4;

Status Simulation::emit() {
  Device& d = *device_;
  const Eigen::Vector3d& g = settings_.gravity;
  double kinetic = 0.0, potential = 0.0;
  bool any = false;
  for (EmitterRange& e : emitters_) {
    const FluidEmitter& f = e.emitter;
    const std::uint64_t by = std::min<std::uint64_t>(emitter_particles_by(f, time_), e.count);
    if (by <= e.emitted) continue;
    const std::size_t per_layer = f.nozzle.size();
    const double mass = 1.0 / static_cast<double>(e.inverse_mass);
    std::vector<vec4> pos, vel;
    for (std::uint64_t k = e.emitted; k < by; ++k) {
      // Layer k / per_layer left at start + layer T: where it is now, as a projectile.
      const double tau =
          std::max(0.0, time_ - (f.start + static_cast<double>(k / per_layer) * f.layer_period));
      const Eigen::Vector3d x = f.position + f.nozzle[k % per_layer] +
                                f.direction * (f.speed * tau) + 0.5 * g * tau * tau;
      const Eigen::Vector3d v = f.direction * f.speed + g * tau;
      pos.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()),
                       static_cast<float>(x.z()), e.radius);
      vel.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()),
                       static_cast<float>(v.z()), e.inverse_mass);
      const Eigen::Vector3d xf =
          Eigen::Vector3f(pos.back().x, pos.back().y, pos.back().z).cast<double>();
      const Eigen::Vector3d vf =
          Eigen::Vector3f(vel.back().x, vel.back().y, vel.back().z).cast<double>();
      kinetic += 0.5 * mass * vf.squaredNorm();
      potential -= mass * g.dot(xf - energy_origin_);
    }
    // Only the new particles' range of the two buffers (32 bytes a particle).
    const std::size_t at = (std::size_t{e.first} + e.emitted) * sizeof(vec4);
    if (Status s = d.write_at(Buffer::ParticlePos, at, pos.data(), pos.size() * sizeof(vec4)); !s) {
      return s;
    }
    if (Status s = d.write_at(Buffer::ParticleVel, at, vel.data(), vel.size() * sizeof(vec4)); !s) {
      return s;
    }
    e.emitted = by;
    any = true;
  }
  if (!any) return Status::ok();
  // The lists know nothing of the new particles: rebuild them at the next update.
  const std::uint32_t rebuild = 1u;
  if (Status s = d.write_at(Buffer::NeighbourState, MOTES_NEIGHBOUR_REBUILD * sizeof rebuild,
                            &rebuild, sizeof rebuild);
      !s) {
    return s;
  }
  // Energy from outside the scene: the guard's reference takes it, and its margin grows as it
  // would have had the particles been there from the start.
  if (energy_started_) {
    energy_reference_.kinetic += kinetic;
    energy_reference_.potential += potential;
    energy_reference_.height += std::max(0.0, potential);
    energy_reference_.margin += kEnergyMarginFraction * (kinetic + std::max(0.0, potential));
  }
  return Status::ok();
}

void Simulation::hide_parked(Snapshot& state) const {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const EmitterRange& e : emitters_) {
    const std::size_t first = bodies_[e.entry].first_particle;
    for (std::uint64_t k = e.emitted; k < e.count; ++k) {
      if (first + k >= state.particle_pos.size()) break;
      shared::vec4& x = state.particle_pos[first + k];
      x = vec4(nan, nan, nan, x.w);
    }
  }
}

Status Simulation::count_emitted() {
  if (emitters_.empty()) return Status::ok();
  std::vector<vec4> vel(sizes_.particles);
  if (Status s = device_->read(Buffer::ParticleVel, vel.data(), vel.size() * sizeof(vec4)); !s) {
    return s;
  }
  for (EmitterRange& e : emitters_) {
    e.emitted = 0;
    while (e.emitted < e.count && vel[e.first + e.emitted].w > 0.0f) ++e.emitted;
  }
  return Status::ok();
}

}  // namespace motes
