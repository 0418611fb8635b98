// contacts_compute: every dynamic particle sums the forces of the particles in its neighbour list,
// in list order (the canonical order of the last build), then the planes. A particle with more
// neighbours than the list holds walks the grid of the last build from the cell of its position
// then: the same pairs in the same order. No atomics: each particle writes only its own force.
// A contact of two particles that list each other is evaluated once, by the lower id, when the
// contact laws are symmetric (contact_pairs.cpp): the same terms, half the work.
// With MOTES_FLAG_POSITION: the shifts of position contacts and their number (contacts_shift.cpp).
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <new>

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
  const bool impulses = (p.flags & MOTES_FLAG_IMPULSE) != 0u;
  const uint rigid = p.rigid_particle_count;
  // A pair of rigid particles under impulse contacts gets no force here from either side.
  const auto no_force = [&](uint a, uint b) { return impulses && a < rigid && b < rigid; };

  // The shared pairs first, each for its lower id; which particles' pairs touch.
  const uint* pair_id = nullptr;
  const vec4* pair_force = nullptr;
  const std::uint8_t* touched = nullptr;
  const uint* unpaired = nullptr;
  if (laws_symmetric(laws, materials) && share_pairs(in, stride, capacity)) {
    contact_pairs_compute(p, in);
    pair_id = contact_pair_id_.data();
    pair_force = contact_pairs_.data();
    touched = contact_touched_.data();
    unpaired = contact_unpaired_.data();
  }

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
    auto add_contact = [&](uint j) {
      if (no_force(uint(i), j)) return;
      const vec4 pj = pos[j];
      const vec4 vj = vel[j];
      f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj),
                                          pj.w, vj.w, law_row[material[j]], p.flags);
    };
    const uint c = count[i];
    // Nothing to add from the list when its pairs all missed and it has no slot of its own.
    const bool quiet = pair_id != nullptr && touched[i] == 0u && unpaired[i] == 0u;
    if (c <= capacity) {
      for (uint k = 0; k < (quiet ? 0u : c); ++k) {
        const std::size_t at = std::size_t{k} * stride + std::size_t(i);
        const uint j = list[at];
        const uint id = pair_id != nullptr ? pair_id[at] : kNoPair;
        if (id == kNoPair) {
          add_contact(j);
        } else if (touched[i] != 0u && !no_force(uint(i), j)) {
          // The lower id's force, or its negation (0 - x: a pair out of contact adds +0 on both
          // sides, as its own evaluation would).
          const vec3 lower = shared::xyz(pair_force[id]);
          const vec3 higher = vec3(0.0f) - lower;
          f += j > uint(i) ? lower : higher;
        }
      }
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
    const bool by_impulse = shared::impulse_particle(p.flags, uint(i), rigid);
    for (uint k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
      const shared::PlaneData pl = planes[k];
      f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                       p.flags);
    }
    force[i] = vec4(f, 0.0f);
  }
  record(Kernel::ContactsCompute, start);
}

void OpenMPDevice::contact_pairs_compute(const shared::StepParams& p, const ContactInputs& in) {
  const auto pairs = static_cast<std::int64_t>(contact_pairs_.size());
  const uint materials = p.material_count;
  const bool impulses = (p.flags & MOTES_FLAG_IMPULSE) != 0u;
  const std::array<uint, 2>* ends = contact_pair_ends_.data();
  vec4* out = contact_pairs_.data();
  std::uint8_t* touched = contact_touched_.data();
  std::fill(contact_touched_.begin(), contact_touched_.end(), std::uint8_t{0});
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(pairs))
  for (std::int64_t q = 0; q < pairs; ++q) {
    const uint a = ends[q][0];
    const uint b = ends[q][1];
    const vec4 pa = in.pos[a];
    const vec4 va = in.vel[a];
    const vec4 pb = in.pos[b];
    const vec4 vb = in.vel[b];
    vec3 f(0.0f);
    // Neither moves (nobody reads it), or two rigid particles under impulse contacts: no force.
    if ((va.w != 0.0f || vb.w != 0.0f) && !(impulses && b < p.rigid_particle_count)) {
      f = shared::particle_contact_force(
          shared::xyz(pa), shared::xyz(va), pa.w, va.w, shared::xyz(pb), shared::xyz(vb), pb.w,
          vb.w, in.laws[std::size_t{in.material[a]} * materials + in.material[b]], p.flags);
    }
    out[q] = vec4(f, 0.0f);
    if (f.x != 0.0f || f.y != 0.0f || f.z != 0.0f) {  // the bytes may be another thread's pair's
      std::atomic_ref<std::uint8_t>(touched[a]).store(1u, std::memory_order_relaxed);
      std::atomic_ref<std::uint8_t>(touched[b]).store(1u, std::memory_order_relaxed);
    }
  }
}

bool OpenMPDevice::laws_symmetric(const shared::ContactLaw* laws, uint materials) {
  const auto same = [](const shared::ContactLaw& a, const shared::ContactLaw& b) {
    return a.stiffness == b.stiffness && a.damping == b.damping && a.tangential == b.tangential &&
           a.friction == b.friction;
  };
  for (uint a = 0; a < materials; ++a) {
    for (uint b = a + 1; b < materials; ++b) {
      if (!same(laws[std::size_t{a} * materials + b], laws[std::size_t{b} * materials + a])) {
        return false;
      }
    }
  }
  return true;
}

bool OpenMPDevice::share_pairs(const ContactInputs& in, std::size_t n, uint capacity) {
  try {
    contact_pairs_index(in, n, capacity);
    return true;
  } catch (const std::bad_alloc&) {  // no room for the pairs: every particle evaluates its own
    contact_pair_id_ = {};
    contact_pair_ends_ = {};
    contact_pairs_ = {};
    contact_unpaired_ = {};
    contact_touched_ = {};
    return false;
  }
}

}  // namespace motes::openmp
