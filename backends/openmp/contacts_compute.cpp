// contacts_compute: every dynamic particle sums the forces of the particles in its neighbour list,
// in list order (the canonical order of the last build), then the planes. A particle with more
// neighbours than the list holds walks the grid of the last build from the cell of its position
// then: the same pairs in the same order. No atomics: each particle writes only its own force.
// With MOTES_FLAG_POSITION: the shifts of position contacts and their number (contacts_shift.cpp).
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/contact_force.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::contacts_compute(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  if ((p.flags & MOTES_FLAG_POSITION) != 0u) {  // position contacts: contacts_shift.cpp
    contacts_shift(p);
    record(Kernel::ContactsCompute, start);
    return;
  }
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const uint materials = p.material_count;
  const ContactInputs in = contact_inputs();  // local copies: the loop reads registers
  const vec4* pos = in.pos;
  const vec4* vel = in.vel;
  const uint* body = in.body;
  const uint* material = in.material;
  const uint* list = in.list;
  const uint* count = in.count;
  const vec4* ref = in.ref;
  const uint* order = in.order;
  const uint* cell_start = in.cell_start;
  const uint* sbody = in.sbody;
  const auto* laws = in.laws;
  const auto* planes = in.planes;
  const uint* exclusions = buf<uint>(Buffer::LinkExclusions);
  vec4* force = buf<vec4>(Buffer::ParticleForce);

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n))
  for (std::int64_t i = 0; i < n; ++i) {
    const vec4 pi = pos[i];
    const vec4 vi = vel[i];
    if (vi.w == 0.0f) {  // static particle: its force is never used
      force[i] = vec4(0.0f);
      continue;
    }
    const vec3 xi = shared::xyz(pi);
    const vec3 ui = shared::xyz(vi);
    const shared::ContactLaw* law_row = laws + std::size_t{material[i]} * materials;
    vec3 f(0.0f);
    // The force of particle j on i (zero unless they overlap), added in order.
    const bool by_impulse = shared::impulse_particle(p.flags, uint(i), p.rigid_particle_count);
    auto add_contact = [&](uint j) {
      if (by_impulse && j < p.rigid_particle_count) return;
      const vec4 pj = pos[j];
      const vec4 vj = vel[j];
      f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj),
                                          pj.w, vj.w, law_row[material[j]], p.flags);
    };
    const uint c = count[i];
    if (c <= capacity) {
      for (uint k = 0; k < c; ++k) add_contact(list[std::size_t{k} * stride + std::size_t(i)]);
    } else {
      const uint body_i = body[i];
      const shared::GridRanges ranges = shared::grid_ranges(p, ref[i], cell_start);
      for (int r = 0; r < ranges.count; ++r) {
        for (uint t = ranges.lo[r]; t < ranges.hi[r]; ++t) {
          const uint j = order[t];
          if (!shared::contact_skipped(body_i, sbody[t], uint(i), j, exclusions, p.particle_count,
                                       p.linked_first)) {
            add_contact(j);
          }
        }
      }
    }
    for (uint k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
      const shared::PlaneData pl = planes[k];
      f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                       p.flags);
    }
    force[i] = vec4(f, 0.0f);
  }
  record(Kernel::ContactsCompute, start);
}

}  // namespace motes::openmp
