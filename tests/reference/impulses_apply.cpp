// The oracle of impulses_apply (reference.h has the contract): each dynamic body's particles'
// impulses and moments summed in float in chunks of MOTES_BODY_CHUNK particles (each in particle
// order, then the chunks in order), then the shared body_apply_contacts
// (body_apply_impulse, or body_apply_position for the projection of position contacts), body after
// body.
#include <algorithm>
#include <cstddef>

#include "reference.h"
#include "shared/impulse.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

void impulses_apply(Bodies& bodies, const StepParams& p, ImpulseState& s,
                    const std::vector<vec4>& pos) {
  const bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const bool push = (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u;
  if (push) {
    s.vel_push.resize(bodies.size(), vec4(0.0f));
    s.angmom_push.resize(bodies.size(), vec4(0.0f));
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    // The contract's order (shared/impulse.h, MOTES_BODY_CHUNK): each chunk of the body's
    // particles in particle order from zero, then the chunks' sums in order.
    vec4 sum(0.0f);
    vec3 m(0.0f);
    motes::shared::ContactGram g = motes::shared::gram_zero();
    if (bodies.pos[b].w != 0.0f) {
      const uint end = bodies.first[b + 1];
      for (uint c = bodies.first[b]; c < end; c += MOTES_BODY_CHUNK) {
        vec4 part(0.0f);
        vec3 part_m(0.0f);
        motes::shared::ContactGram part_g = motes::shared::gram_zero();
        for (uint i = c; i < std::min(c + MOTES_BODY_CHUNK, end); ++i) {
          part = part + s.impulse[i];
          part_m += xyz(s.moment[i]);
          if (gram) {
            motes::shared::gram_add(part_g, s.impulse[i], s.moment[i],
                                    xyz(pos.at(i)) - xyz(bodies.pos[b]));
          }
        }
        sum = sum + part;
        m += part_m;
        motes::shared::gram_merge(g, part_g);
      }
    }
    if (counting) {
      s.vel0[b] = motes::shared::impulse_start_velocity(bodies.vel[b], s.vel0[b], sum.w, p.flags);
      s.angvel0[b] =
          motes::shared::impulse_start_angular_velocity(bodies.angvel[b], s.angvel0[b], p.flags);
      if (gram) {
        s.angvel0[b].w =
            motes::shared::gram_bound(g, bodies.pos[b], bodies.quat[b], bodies.inv_inertia[b]);
      }
      if (bodies.pos[b].w != 0.0f) {
        for (uint i = bodies.first[b]; i < bodies.first[b + 1]; ++i) s.stamp[i] = s.builds;
      }
    }
    motes::shared::body_apply_contacts(bodies.pos[b], bodies.quat[b], bodies.inv_inertia[b],
                                       bodies.vel[b], bodies.angmom[b], bodies.angvel[b], xyz(sum),
                                       m, p.gravity_dt, p.flags);
    if (push) {
      s.vel_push[b] = bodies.vel[b];
      s.angmom_push[b] = bodies.angmom[b];
    }
  }
}

}  // namespace motes_ref
