// The oracle of constraints_solve (reference.h has the contract): one colour's constraints
// projected one after the other.
#include <cstddef>
#include <stdexcept>

#include "reference.h"
#include "shared/neighbours.h"

namespace motes_ref {

bool constraints_solve(Particles& particles, const std::vector<Constraint>& constraints,
                       const StepParams& p, const std::vector<vec4>& ref) {
  const float inv_dt = 1.0f / p.gravity_dt.w;
  std::vector<bool> used(particles.size(), false);
  bool moved = false;
  for (std::size_t k = p.constraint_first; k < p.constraint_first + p.constraint_count; ++k) {
    const Constraint c = constraints[k];
    if (used[c.a] || used[c.b] || c.a == c.b) {
      throw std::invalid_argument(
          "constraints_solve: two constraints of one colour share a particle");
    }
    used[c.a] = used[c.b] = true;
    motes::shared::constraint_project(particles.pos[c.a], particles.pos[c.b], particles.vel[c.a],
                                      particles.vel[c.b], c, inv_dt);
    for (const uint i : {c.a, c.b}) {
      if (!ref.empty() && (p.flags & MOTES_FLAG_SKIN_CHECK) != 0) {
        moved =
            motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
            moved;
      }
    }
  }
  return moved;
}

}  // namespace motes_ref
