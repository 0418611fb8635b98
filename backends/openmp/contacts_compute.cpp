// contacts_compute: every dynamic particle sums the forces of the particles in its neighbour list,
// in list order (the canonical order of the last build), then the planes. A particle with more
// neighbours than the list holds walks the grid of the last build from the cell of its position
// then: the same pairs in the same order. No atomics: each particle writes only its own force.
// A contact of two particles that list each other is evaluated once, by the lower id, when the
// contact laws are symmetric (contact_pairs.cpp): the same terms, half the work.
// A particle tests only the planes it may touch before the next list build (plane_masks.cpp): a
// plane it skips would have added exactly 0.
// With MOTES_FLAG_POSITION: the shifts of position contacts and their number (contacts_shift.cpp).
#include <bit>
#include <chrono>
#include <cstdint>
#include <new>

#include "openmp_device.h"
#include "shared/contact_force.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::openmp {

namespace {

// particle_contact_force's own first test (apart: no force), made before the partner's velocity
// and material are read: most list entries are apart while particles fall.
bool apart(const shared::vec4& a, const shared::vec4& b) {
  const shared::vec3 d = shared::xyz(b) - shared::xyz(a);
  const float reach = a.w + b.w;
  return shared::dot(d, d) >= reach * reach;
}

}  // namespace

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
  const std::uint32_t* plane_mask = plane_masks(p, ref);
  // A pair of rigid particles under impulse contacts gets no force here from either side.
  const auto no_force = [&](uint a, uint b) { return impulses && a < rigid && b < rigid; };

  // Every list slot's term first: a shared pair's for both its slots, the others by their own.
  // Worth it when at least half the entries touched at the last call (a dense pile; not while
  // they fall apart, where a slot's write and read cost more than the distance it saves). Both
  // ways give the same sums, and the choice follows the counts: deterministic.
  const uint* slot_first = nullptr;
  const vec3* slot_force = nullptr;
  std::uint64_t touching = 0;
  std::uint64_t entries = 0;
  const bool worth = shared_pairs_ == SharedPairs::Always ||
                     (shared_pairs_ == SharedPairs::Auto && contact_entries_ > 0 &&
                      2 * contact_touching_ >= contact_entries_);
  if (worth && laws_symmetric(laws, materials) && share_pairs(in, stride, capacity)) {
    touching = contact_slots_compute(p, in);
    entries = contact_slot_force_.size();
    slot_first = contact_slot_first_.data();
    slot_force = contact_slot_force_.data();
  }

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n)) \
    reduction(+ : touching, entries)
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
      if (apart(pi, pj)) return;
      ++touching;
      const vec4 vj = vel[j];
      f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj),
                                          pj.w, vj.w, law_row[material[j]], p.flags);
    };
    const uint c = count[i];
    if (c <= capacity && slot_force != nullptr) {
      for (uint s = slot_first[i]; s < slot_first[i + 1]; ++s) f += slot_force[s];
    } else if (c <= capacity) {
      for (uint k = 0; k < c; ++k) add_contact(list[std::size_t{k} * stride + std::size_t(i)]);
      entries += c;
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
    if (!by_impulse && plane_mask != nullptr) {  // the planes in reach, in order
      for (std::uint32_t m = plane_mask[i]; m != 0u; m &= m - 1u) {
        const shared::PlaneData pl = planes[std::countr_zero(m)];
        f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                         p.flags);
      }
    } else {
      for (uint k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
        const shared::PlaneData pl = planes[k];
        f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                         p.flags);
      }
    }
    force[i] = vec4(f, 0.0f);
  }
  contact_touching_ = touching;
  contact_entries_ = entries;
  record(Kernel::ContactsCompute, start);
}

std::uint64_t OpenMPDevice::contact_slots_compute(const shared::StepParams& p,
                                                  const ContactInputs& in) {
  const uint materials = p.material_count;
  const std::size_t stride = p.particle_count;
  const bool impulses = (p.flags & MOTES_FLAG_IMPULSE) != 0u;
  const uint rigid = p.rigid_particle_count;
  vec3* out = contact_slot_force_.data();
  // The force on particle a from b, or 0: neither moves (nobody reads it), or two rigid particles
  // under impulse contacts (impulses_compute has them).
  const auto term = [&](uint a, uint b) {
    const vec4 pa = in.pos[a];
    const vec4 pb = in.pos[b];
    if (apart(pa, pb)) return vec3(0.0f);
    const vec4 va = in.vel[a];
    const vec4 vb = in.vel[b];
    if ((va.w == 0.0f && vb.w == 0.0f) || (impulses && a < rigid && b < rigid)) return vec3(0.0f);
    return shared::particle_contact_force(
        shared::xyz(pa), shared::xyz(va), pa.w, va.w, shared::xyz(pb), shared::xyz(vb), pb.w, vb.w,
        in.laws[std::size_t{in.material[a]} * materials + in.material[b]], p.flags);
  };
  const ContactPair* pairs = contact_pair_list_.data();
  const auto pair_count = static_cast<std::int64_t>(contact_pair_list_.size());
  std::uint64_t touching = 0;
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(pair_count)) \
    reduction(+ : touching)
  for (std::int64_t q = 0; q < pair_count; ++q) {
    const ContactPair pr = pairs[q];
    const vec3 f = term(pr.a, pr.b);
    touching += f.x != 0.0f || f.y != 0.0f || f.z != 0.0f ? 2u : 0u;
    out[pr.slot_a] = f;
    // 0 - f: a pair out of contact gives +0 on both sides, as each side's own evaluation would.
    out[pr.slot_b] = vec3(0.0f) - f;
  }
  const ContactSlot* own = contact_own_slots_.data();
  const auto own_count = static_cast<std::int64_t>(contact_own_slots_.size());
  const uint* first = contact_slot_first_.data();
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(own_count)) \
    reduction(+ : touching)
  for (std::int64_t q = 0; q < own_count; ++q) {
    const ContactSlot sl = own[q];
    const uint j = in.list[std::size_t{sl.k} * stride + sl.i];
    const vec3 f = term(sl.i, j);
    touching += f.x != 0.0f || f.y != 0.0f || f.z != 0.0f ? 1u : 0u;
    out[first[sl.i] + sl.k] = f;
  }
  return touching;
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
    return contact_pairs_index(in, n, capacity);
  } catch (const std::bad_alloc&) {  // no room for the pairs: every particle evaluates its own
    contact_pairs_ready_ = false;
    contact_slot_first_ = {};
    contact_pair_list_ = {};
    contact_own_slots_ = {};
    contact_slot_force_ = {};
    return false;
  }
}

}  // namespace motes::openmp
