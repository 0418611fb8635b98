// contacts_compute with MOTES_FLAG_POSITION (shared/particle_shift.h): every dynamic particle sums
// the shifts its position contacts ask of it, with their number in w, in the order contacts_compute
// sums forces (list order, or the grid walk beyond the list's capacity, then the planes); a rigid
// body's particle sums the reactions of its contacts with other kinds' particles instead (its
// contacts with rigid particles and planes are impulses_compute's). A loop of
// its own beside the force law's, which keeps its code (one loop for both made the force law's
// falling spheres slower).
#include <cstdint>

#include "openmp_device.h"
#include "shared/contact_force.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::contacts_shift(const shared::StepParams& p) {
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const uint materials = p.material_count;
  const ContactInputs in = contact_inputs();
  const uint* exclusions = buf<uint>(Buffer::LinkExclusions);
  vec4* sums = buf<vec4>(Buffer::ParticleForce);
  const float h = p.gravity_dt.w;

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
  for (std::int64_t i = 0; i < n; ++i) {
    const vec4 pi = in.pos[i];
    const vec4 vi = in.vel[i];
    if (vi.w == 0.0f) {  // static particle: nothing to move
      sums[i] = vec4(0.0f);
      continue;
    }
    const vec3 xi = shared::xyz(pi);
    const vec3 ui = shared::xyz(vi);
    const shared::ContactLaw* law_row = in.laws + std::size_t{in.material[i]} * materials;
    const bool by_impulse = shared::impulse_particle(p.flags, uint(i), p.rigid_particle_count);
    // Both particles' contacts within reach: mass splitting.
    const float ni = shared::particle_shift_count(in.count[i], p.plane_count);
    vec4 s(0.0f);
    // A rigid body's particle gathers the reactions of its contacts with other kinds' particles.
    const bool rigid = uint(i) < p.rigid_particle_count;
    auto add_contact = [&](uint j) {
      if (by_impulse && j < p.rigid_particle_count) return;
      if (shared::shift_pair_skipped(uint(i), j, p.fluid_first, p.fluid_count)) return;
      const vec4 pj = in.pos[j];
      const vec4 vj = in.vel[j];
      const float nj = shared::particle_shift_count(in.count[j], p.plane_count);
      if (rigid) {
        s += shared::rigid_contact_reaction(
            xi, ui, pi.w, ni, shared::xyz(pj), shared::xyz(vj), pj.w, vj.w, nj,
            in.laws[std::size_t{in.material[j]} * materials + in.material[i]], h);
      } else {
        s += shared::particle_contact_shift(
            xi, ui, pi.w, vi.w, ni, shared::xyz(pj), shared::xyz(vj), pj.w,
            shared::shift_partner_inverse_mass(j, p.rigid_particle_count, vj.w), nj,
            law_row[in.material[j]], h);
      }
    };
    const uint c = in.count[i];
    if (c <= capacity) {
      for (uint k = 0; k < c; ++k) add_contact(in.list[std::size_t{k} * stride + std::size_t(i)]);
    } else {
      const uint body_i = in.body[i];
      const shared::GridRanges ranges = shared::grid_ranges(p, in.ref[i], in.cell_start);
      for (int r = 0; r < ranges.count; ++r) {
        for (uint t = ranges.lo[r]; t < ranges.hi[r]; ++t) {
          const uint j = in.order[t];
          if (!shared::contact_skipped(body_i, in.sbody[t], uint(i), j, exclusions,
                                       p.particle_count, p.linked_first)) {
            add_contact(j);
          }
        }
      }
    }
    for (uint k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
      const shared::PlaneData pl = in.planes[k];
      s += shared::plane_contact_shift(xi, ui, pi.w, ni, pl.normal_offset, law_row[pl.material], h);
    }
    sums[i] = s;
  }
}

}  // namespace motes::openmp
