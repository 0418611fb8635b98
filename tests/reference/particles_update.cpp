// The oracle of particles_update (reference.h has the contract): the rigid particles placed from
// their bodies' poses one after the other, and with MOTES_FLAG_ABSORB the impulses their
// velocities hand to their bodies (absorbed_impulses).
#include <cstddef>

#include "reference.h"
#include "shared/body_math.h"
#include "shared/neighbours.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

bool particles_update(const Bodies& bodies, Particles& particles, const StepParams& p,
                      const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t i = 0; i < particles.rigid; ++i) {
    const uint b = particles.body[i];
    const vec4 local = particles.local[i];
    particles.pos[i] = vec4(motes::shared::particle_position(bodies.pos[b], bodies.quat[b], local),
                            particles.pos[i].w);
    particles.vel[i] = vec4(
        motes::shared::particle_velocity(bodies.quat[b], bodies.vel[b], bodies.angvel[b], local),
        particles.vel[i].w);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

void absorbed_impulses(const Bodies& bodies, const Particles& particles, std::vector<vec4>& impulse,
                       std::vector<vec4>& moment, const std::vector<vec4>& reactions) {
  impulse.assign(particles.rigid, vec4(0.0f));
  moment.assign(particles.rigid, vec4(0.0f));
  for (std::size_t i = 0; i < particles.rigid; ++i) {
    const uint b = particles.body[i];
    const vec3 j = !reactions.empty() ? xyz(reactions[i])
                                      : motes::shared::particle_absorbed_impulse(
                                            particles.vel[i], bodies.quat[b], bodies.vel[b],
                                            bodies.angvel[b], particles.local[i]);
    impulse[i] = vec4(j, 0.0f);
    const vec3 r = motes::shared::quat_rotate(bodies.quat[b], xyz(particles.local[i]));
    moment[i] = vec4(motes::shared::cross(r, j), 0.0f);
  }
}

}  // namespace motes_ref
