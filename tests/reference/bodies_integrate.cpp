// The oracle of bodies_integrate (reference.h has the contract): the shared body_integrate, or
// body_push_pose with the impulse stage's pushed velocities, or body_split_pose, on every body in
// turn.
#include <cstddef>

#include "reference.h"
#include "shared/body_math.h"

namespace motes_ref {

void bodies_integrate(Bodies& bodies, const StepParams& p) {
  bodies.angvel.assign(bodies.size(), vec4(0.0f));
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    motes::shared::body_integrate(bodies.pos[b], bodies.quat[b], bodies.vel[b], bodies.angmom[b],
                                  bodies.angvel[b], bodies.inv_inertia[b], bodies.force[b],
                                  bodies.torque[b], p.gravity_dt, p.flags);
  }
}

void bodies_push_pose(Bodies& bodies, std::vector<vec4>& pos_low, const std::vector<vec4>& vel_push,
                      const std::vector<vec4>& angmom_push, const StepParams& p) {
  bodies.angvel.assign(bodies.size(), vec4(0.0f));
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    motes::shared::body_push_pose(bodies.pos[b], pos_low[b], bodies.quat[b], bodies.angvel[b],
                                  bodies.inv_inertia[b], bodies.angmom[b], vel_push[b],
                                  angmom_push[b], p.gravity_dt);
  }
}

void bodies_split_pose(Bodies& bodies, std::vector<vec4>& pos_low,
                       const std::vector<vec4>& vel_push, const std::vector<vec4>& angmom_push,
                       const StepParams& p) {
  bodies.angvel.assign(bodies.size(), vec4(0.0f));
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    motes::shared::body_split_pose(bodies.pos[b], pos_low[b], bodies.quat[b], bodies.vel[b],
                                   bodies.angmom[b], bodies.angvel[b], bodies.inv_inertia[b],
                                   vel_push[b], angmom_push[b], p.gravity_dt);
  }
}

}  // namespace motes_ref
