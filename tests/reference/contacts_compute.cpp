// The oracle of contacts_compute (reference.h has the contract): O(N^2) over all pairs, no grid,
// each particle's terms summed in double in id order and rounded once.
#include <cstddef>

#include "reference.h"
#include "shared/contact_force.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

std::vector<vec4> contacts_compute(const Particles& particles, const std::vector<ContactLaw>& laws,
                                   const std::vector<PlaneData>& planes, const StepParams& p,
                                   const std::vector<uint>& listed) {
  const auto within_reach = [&](std::size_t i) {
    return (p.flags & MOTES_FLAG_POSITION) != 0u
               ? motes::shared::particle_shift_count(listed.at(i), p.plane_count)
               : 0.0f;
  };
  const std::size_t n = particles.size();
  const std::size_t m = p.material_count;
  std::vector<vec4> force(n, vec4(0.0f));
  for (std::size_t i = 0; i < n; ++i) {
    const vec4 xi = particles.pos[i];
    const vec4 vi = particles.vel[i];
    if (vi.w == 0.0f) continue;  // static particles get no force
    double sum[4] = {0.0, 0.0, 0.0, 0.0};
    auto add = [&](vec4 f) {
      sum[0] += static_cast<double>(f.x);
      sum[1] += static_cast<double>(f.y);
      sum[2] += static_cast<double>(f.z);
      sum[3] += static_cast<double>(f.w);
    };
    const float h = p.gravity_dt.w;
    const float ni = within_reach(i);
    const bool positions = (p.flags & MOTES_FLAG_POSITION) != 0u;
    const auto rigid = static_cast<uint>(particles.rigid);
    // A rigid body's particle in a scene of rigid contacts without forces: its contacts with
    // rigid particles and planes are impulses_compute's.
    const bool by_impulse = motes::shared::impulse_particle(p.flags, uint(i), rigid);
    for (std::size_t j = 0; j < n; ++j) {
      if (by_impulse && j < rigid) continue;
      if (positions &&
          motes::shared::shift_pair_skipped(uint(i), uint(j), p.fluid_first, p.fluid_count)) {
        continue;  // two fluid particles: the density constraint's
      }
      const vec4 xj = particles.pos[j];
      // Apart along x by the radii's sum or more: the term is 0 (its float
      // dx * dx alone reaches rsum * rsum), which adds nothing.
      const float dx = xj.x - xi.x;
      if (dx >= xi.w + xj.w || -dx >= xi.w + xj.w) continue;
      const vec4 vj = particles.vel[j];
      const ContactLaw law = laws[particles.material[i] * m + particles.material[j]];
      // Position contacts: a rigid body's particle takes the reaction of its partner's shift, and
      // a rigid partner does not move in the shift (shared/particle_shift.h).
      const vec4 f =
          !positions
              ? vec4(motes::shared::particle_contact_force(xyz(xi), xyz(vi), xi.w, vi.w, xyz(xj),
                                                           xyz(vj), xj.w, vj.w, law, p.flags),
                     0.0f)
          : i < rigid
              ? motes::shared::rigid_contact_reaction(
                    xyz(xi), xyz(vi), xi.w, ni, xyz(xj), xyz(vj), xj.w, vj.w, within_reach(j),
                    laws[particles.material[j] * m + particles.material[i]], h)
              : motes::shared::particle_contact_shift(
                    xyz(xi), xyz(vi), xi.w, vi.w, ni, xyz(xj), xyz(vj), xj.w,
                    motes::shared::shift_partner_inverse_mass(uint(j), rigid, vj.w),
                    within_reach(j), law, h);
      // A zero term adds nothing (the sum starts at +0 and so is never -0): the exclusions, a set
      // lookup, are asked only of pairs that touch.
      if (f.x == 0.0f && f.y == 0.0f && f.z == 0.0f && f.w == 0.0f) continue;
      if (motes::shared::contact_excluded(particles.body[j], particles.body[i]) ||
          particles.never_touch.count({uint(i), uint(j)}) != 0) {
        continue;  // j == i, or j never touches i
      }
      add(f);
    }
    for (std::size_t k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
      const ContactLaw law = laws[particles.material[i] * m + planes[k].material];
      add(motes::shared::plane_contact_term(xyz(xi), xyz(vi), xi.w, vi.w, ni,
                                            planes[k].normal_offset, law, p.flags, h));
    }
    force[i] = vec4(static_cast<float>(sum[0]), static_cast<float>(sum[1]),
                    static_cast<float>(sum[2]), static_cast<float>(sum[3]));
  }
  return force;
}

}  // namespace motes_ref
