// The oracle of particles_integrate (reference.h has the contract): the free particles one
// after the other, the linked ones damped first; with MOTES_FLAG_PARTICLE_SHIFT each moved by the
// mean of its contacts' shifts instead.
#include <cstddef>

#include "reference.h"
#include "shared/body_math.h"
#include "shared/neighbours.h"
#include "shared/particle_shift.h"

namespace motes_ref {

bool particles_integrate(Particles& particles, const std::vector<vec4>& force, const StepParams& p,
                         const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t i = particles.rigid; i < particles.size(); ++i) {
    if ((p.flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {  // the mean of the contacts' shifts
      motes::shared::particle_shift_apply(particles.pos[i], particles.vel[i], force[i],
                                          p.gravity_dt.w);
    } else if (i >= p.linked_first) {  // cloth and rope particles: Jakobsen's damping first
      const vec4 v = particles.vel[i];
      const float keep = 1.0f - p.linked_damping;
      particles.vel[i] = vec4(v.x * keep, v.y * keep, v.z * keep, v.w);
    }
    if ((p.flags & MOTES_FLAG_PARTICLE_SHIFT) == 0u) {
      motes::shared::particle_integrate(particles.pos[i], particles.vel[i], force[i], p.gravity_dt,
                                        p.flags);
    }
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

}  // namespace motes_ref
