// The oracle of particles_integrate (reference.h has the contract): the free particles one
// after the other, the linked ones damped first.
#include <cstddef>

#include "reference.h"
#include "shared/body_math.h"
#include "shared/neighbours.h"

namespace motes_ref {

bool particles_integrate(Particles& particles, const std::vector<vec4>& force, const StepParams& p,
                         const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t i = particles.rigid; i < particles.size(); ++i) {
    if (i >= p.linked_first) {  // cloth and rope particles: Jakobsen's damping first
      const vec4 v = particles.vel[i];
      const float keep = 1.0f - p.linked_damping;
      particles.vel[i] = vec4(v.x * keep, v.y * keep, v.z * keep, v.w);
    }
    motes::shared::particle_integrate(particles.pos[i], particles.vel[i], force[i], p.gravity_dt);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

}  // namespace motes_ref
