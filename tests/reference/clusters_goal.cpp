// The oracle of clusters_goal (reference.h has the contract): every member's pull and damping
// found by scanning all members in order (not through ClusterGather), then applied.
#include <stdexcept>

#include "reference.h"
#include "shared/neighbours.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

bool clusters_goal(Particles& particles, const std::vector<ClusterMember>& members,
                   const std::vector<ClusterFrame>& frames, const StepParams& p,
                   const std::vector<vec4>& ref) {
  std::vector<vec3> shift(particles.size(), vec3(0.0f));
  std::vector<vec3> damp(particles.size(), vec3(0.0f));
  for (const ClusterMember& m : members) {
    if (m.particle < p.soft_first || m.particle >= p.linked_first) {
      throw std::invalid_argument("clusters_goal: a member outside the soft particles");
    }
    const vec3 x = xyz(particles.pos[m.particle]);
    const vec4 v = particles.vel[m.particle];
    shift[m.particle] += motes::shared::cluster_shift(frames[m.cluster], m, x, v.w);
    damp[m.particle] += motes::shared::cluster_damp(frames[m.cluster], m, x, xyz(v), v.w);
  }
  const float inv_dt = 1.0f / p.gravity_dt.w;
  bool moved = false;
  for (uint i = p.soft_first; i < p.linked_first; ++i) {
    particles.vel[i] = vec4(xyz(particles.vel[i]) + damp[i], particles.vel[i].w);
    motes::shared::constraint_apply(particles.pos[i], particles.vel[i], shift[i], inv_dt);
    if (!ref.empty()) {
      moved = motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin) ||
              moved;
    }
  }
  return moved;
}

}  // namespace motes_ref
