// The oracle of the impulse families (impulses_compute, impulses_apply): reference.h has the
// contracts. Naive loops over the oracle's full neighbour lists; the physics comes from
// shaders/shared/impulse.h, as on every backend.
#include <cstddef>

#include "reference.h"
#include "shared/impulse.h"

namespace motes_ref {

using motes::shared::ImpulseBody;
using motes::shared::vec3;
using motes::shared::xyz;

namespace {

ImpulseBody impulse_body(const Bodies& bodies, const ImpulseState& s, uint b, uint flags) {
  return motes::shared::impulse_body_of(bodies.pos[b], bodies.quat[b], bodies.inv_inertia[b],
                                        bodies.vel[b], bodies.angvel[b], s.vel0[b], s.angvel0[b],
                                        flags);
}

}  // namespace

void impulses_compute(const Particles& particles, const Bodies& bodies, const Neighbours& nb,
                      const std::vector<ContactLaw>& laws, const std::vector<PlaneData>& planes,
                      const StepParams& p, ImpulseState& s) {
  const std::size_t nr = particles.rigid;
  const uint capacity = p.neighbour_capacity;
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const float margin = motes::shared::impulse_margin(p.neighbour_skin);
  s.impulse.assign(nr, vec4(0.0f));
  s.moment.assign(nr, vec4(0.0f));
  for (std::size_t i = 0; i < nr; ++i) {
    if (particles.vel[i].w == 0.0f) continue;
    const vec4 xi = particles.pos[i];
    const ImpulseBody own = impulse_body(bodies, s, particles.body[i], p.flags);
    vec4 sum(0.0f);
    vec3 moment(0.0f);
    const std::vector<uint>& list = nb.lists[i];
    for (std::size_t k = 0; k < list.size(); ++k) {
      const uint j = list[k];
      if (j >= nr) continue;
      const bool slotted = motes::shared::impulse_pair_slotted(nb.count[i], nb.count[j], capacity);
      vec4& slot = s.acc[k * nr + i];  // only touched when slotted (then k < K)
      const bool valid = !counting || motes::shared::impulse_slots_valid(
                                          s.stamp[i], s.stamp[j], particles.vel[j].w, s.builds);
      vec4 a = slotted && valid ? slot : vec4(0.0f);
      const uint law = motes::shared::pair_law_index(static_cast<uint>(i), particles.material[i], j,
                                                     particles.material[j], p.material_count);
      const vec4 r = motes::shared::pair_impulse(
          own, xi, impulse_body(bodies, s, particles.body[j], p.flags), particles.pos[j], i < j,
          margin, laws[law], p.gravity_dt, p.flags, a);
      if (slotted) slot = a;
      motes::shared::impulse_add(sum, moment, r,
                                 motes::shared::pair_contact_point(xi, particles.pos[j]), own.com);
    }
    for (std::size_t k = 0; k < planes.size(); ++k) {
      const PlaneData& pl = planes[k];
      vec4& a = s.acc[(capacity + k) * nr + i];
      const vec4 r = motes::shared::plane_contact_impulse(
          own, xi, pl.normal_offset, margin,
          laws[std::size_t{particles.material[i]} * p.material_count + pl.material], p.gravity_dt,
          p.flags, a);
      motes::shared::impulse_add(sum, moment, r,
                                 motes::shared::plane_contact_point(xi, pl.normal_offset), own.com);
    }
    s.impulse[i] = sum;
    s.moment[i] = vec4(moment, 0.0f);
  }
}

void impulses_apply(Bodies& bodies, const StepParams& p, ImpulseState& s) {
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  const bool push = (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u;
  if (push) {
    s.vel_push.resize(bodies.size(), vec4(0.0f));
    s.angmom_push.resize(bodies.size(), vec4(0.0f));
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    vec4 sum(0.0f);
    vec3 m(0.0f);
    if (bodies.pos[b].w != 0.0f) {
      for (uint i = bodies.first[b]; i < bodies.first[b + 1]; ++i) {
        sum = sum + s.impulse[i];
        m += xyz(s.moment[i]);
      }
    }
    if (counting) {
      s.vel0[b] = vec4(xyz(bodies.vel[b]), sum.w);
      s.angvel0[b] = bodies.angvel[b];
      if (bodies.pos[b].w != 0.0f) {
        for (uint i = bodies.first[b]; i < bodies.first[b + 1]; ++i) s.stamp[i] = s.builds;
      }
    }
    motes::shared::body_apply_impulse(bodies.pos[b], bodies.quat[b], bodies.inv_inertia[b],
                                      bodies.vel[b], bodies.angmom[b], bodies.angvel[b], xyz(sum),
                                      m);
    if (push) {
      s.vel_push[b] = bodies.vel[b];
      s.angmom_push[b] = bodies.angmom[b];
    }
  }
}

void impulse_stamps_after_build(const Particles& particles, const std::vector<uint>& old_list,
                                const std::vector<uint>& old_count, const Neighbours& now,
                                const StepParams& p, uint built, std::vector<uint>& stamp) {
  const std::size_t n = now.count.size();
  for (std::size_t i = 0; i < stamp.size() && i < n; ++i) {
    if (stamp[i] != built || particles.vel[i].w == 0.0f) continue;
    const std::vector<uint>& list = now.lists[i];
    bool same = true;
    for (std::size_t k = 0; k < list.size() && k < p.neighbour_capacity; ++k) {
      same = same && old_list[k * n + i] == list[k];
    }
    if (motes::shared::neighbour_keeps_slots(old_count[i], now.count[i], same,
                                             p.neighbour_capacity)) {
      stamp[i] = built + 1u;
    }
  }
}

}  // namespace motes_ref
