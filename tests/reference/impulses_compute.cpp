// The oracle of impulses_compute (reference.h has the contract): naive loops over the oracle's
// full neighbour lists; the physics comes from shaders/shared/impulse.h, as on every backend.
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

/// Rigid particle i as its contacts take it (shared::contact_particle).
vec4 particle(const Particles& particles, const Bodies& bodies, std::size_t i, uint flags) {
  return motes::shared::contact_particle(particles.pos[i], bodies.quat[particles.body[i]],
                                         particles.local[i], flags);
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
  // The accumulated impulses this pass keeps (split impulses' correcting sweeps: acc_split), and
  // where it copies them (the last relaxing sweep).
  const bool split = (p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u;
  const bool copy = (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u;
  if (split || copy) s.acc_split.resize(s.acc.size(), vec4(0.0f));
  std::vector<vec4>& acc = split ? s.acc_split : s.acc;
  const auto keep = [&](std::size_t at, const vec4& a) {
    acc[at] = a;
    if (copy) s.acc_split[at] = a;
  };
  for (std::size_t i = 0; i < nr; ++i) {
    if (particles.vel[i].w == 0.0f) continue;
    const vec4 xi = particle(particles, bodies, i, p.flags);
    const ImpulseBody own = impulse_body(bodies, s, particles.body[i], p.flags);
    vec4 sum(0.0f);
    vec3 moment(0.0f);
    const std::vector<uint>& list = nb.lists[i];
    for (std::size_t k = 0; k < list.size(); ++k) {
      const uint j = list[k];
      if (j >= nr) continue;
      const bool slotted = motes::shared::impulse_pair_slotted(nb.count[i], nb.count[j], capacity);
      const std::size_t at = k * nr + i;  // only touched when slotted (then k < K)
      const bool valid = !counting || motes::shared::impulse_slots_valid(
                                          s.stamp[i], s.stamp[j], particles.vel[j].w, s.builds);
      vec4 a = slotted && valid ? acc[at] : vec4(0.0f);
      const uint law = motes::shared::pair_law_index(static_cast<uint>(i), particles.material[i], j,
                                                     particles.material[j], p.material_count);
      vec3 arm;
      const vec4 r =
          motes::shared::pair_impulse(own, xi, impulse_body(bodies, s, particles.body[j], p.flags),
                                      particle(particles, bodies, j, p.flags), i < j, margin,
                                      laws[law], p.gravity_dt, p.flags, a, arm);
      if (slotted) keep(at, a);
      motes::shared::impulse_add(sum, moment, r, arm, p.flags);
    }
    for (std::size_t k = 0; k < planes.size(); ++k) {
      const PlaneData& pl = planes[k];
      const std::size_t at = (capacity + k) * nr + i;
      vec4 a = acc[at];
      vec3 arm;
      const vec4 r = motes::shared::plane_contact_impulse(
          own, xi, pl.normal_offset, margin,
          laws[std::size_t{particles.material[i]} * p.material_count + pl.material], p.gravity_dt,
          p.flags, a, arm);
      keep(at, a);
      motes::shared::impulse_add(sum, moment, r, arm, p.flags);
    }
    s.impulse[i] = sum;
    s.moment[i] = vec4(moment, 0.0f);
  }
}

}  // namespace motes_ref
