// The oracle of bodies_reduce (reference.h has the contract): each body's particles summed in
// float in particle order.
#include <cstddef>

#include "reference.h"
#include "shared/body_math.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

void bodies_reduce(const std::vector<vec4>& particle_pos, const std::vector<vec4>& particle_force,
                   Bodies& bodies) {
  const std::size_t count = bodies.size();
  bodies.force.assign(count, vec4(0.0f));
  bodies.torque.assign(count, vec4(0.0f));
  for (std::size_t b = 0; b < count; ++b) {
    const vec4 com = bodies.pos[b];
    if (com.w == 0.0f) continue;  // static bodies: nothing to integrate, zero sums
    vec3 f(0.0f);
    vec3 tau(0.0f);
    for (uint i = bodies.first[b]; i < bodies.first[b + 1]; ++i) {
      f += xyz(particle_force[i]);
      tau += motes::shared::particle_torque(particle_pos[i], com, particle_force[i]);
    }
    bodies.force[b] = vec4(f, 0.0f);
    bodies.torque[b] = vec4(tau, 0.0f);
  }
}

}  // namespace motes_ref
