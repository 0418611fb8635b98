// What several families' oracles share: one whole step in the core's order (reference.h).
#include "reference.h"

namespace motes_ref {

void step(Particles& particles, Bodies& bodies, const std::vector<ContactLaw>& laws,
          const std::vector<PlaneData>& planes, const StepParams& p) {
  const std::vector<vec4> force = contacts_compute(particles, laws, planes, p);
  bodies_reduce(particles.pos, force, bodies);
  bodies_integrate(bodies, p);
  particles_update(bodies, particles, p);
  particles_integrate(particles, force, p);
}

}  // namespace motes_ref
