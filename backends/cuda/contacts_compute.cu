// contacts_compute: every dynamic particle (one thread per particle id) sums the forces of the
// particles in its neighbour list, in list order, then the planes, and writes only its own force:
// no atomics, a fixed summation order. A particle with more neighbours than its list holds walks
// the grid of the last build from the cell of its position then: the same pairs in the same order.
// As backends/openmp/contacts_compute.cpp and shaders/contacts_compute.comp. The list's entry k of
// particle i is at k * N + i, so a warp's loads of its k-th entries are one coalesced read.
#include <type_traits>

#include "cuda_device.h"
#include "shared/contact_force.h"
#include "shared/grid_walk.h"
#include "shared/links.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

/// exclusions: LinkExclusions (shared/links.h), for the grid walk; not __restrict__, as when it was
/// a member of the inputs (a __restrict__ parameter moves its loads to the read-only path).
/// kShifts: position contacts (MOTES_FLAG_POSITION: shifts and their number, shared/
/// particle_shift.h); a kernel of its own, so that the force law's keeps its registers and loads
/// (one kernel for both made the force law's 1 M falling spheres 10% slower on an H200).
/// The force law's kernel is held to 5 blocks of kBlock threads an SM (at most 51 registers: it
/// takes 48; left free it took 56, and 4 blocks fitted): W1 falling at 16.8 M 1.195 -> 1.059
/// ms/step on an H200, dense at 1 M 0.168 -> 0.155 (6 blocks, 40 registers and a larger stack:
/// falling 0.973, dense 0.212). docs/benchmarks.md, "Registers and occupancy". The shifts' kernel
/// is held to no fewer than 1 block (61 registers, 63 before: 4 blocks an SM either way).
template <bool kShifts>
__global__ void __launch_bounds__(CudaDevice::kBlock, kShifts ? 1 : 5)
    contacts_compute_kernel(shared::StepParams p, ContactInputs in, const uint* exclusions,
                            vec4* __restrict__ force) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (i >= p.particle_count) return;
  const vec4 pi = in.pos[i];
  const vec4 vi = in.vel[i];
  if (vi.w == 0.0f) {  // static particle: its force is never used
    force[i] = vec4(0.0f);
    return;
  }
  const vec3 xi = shared::xyz(pi);
  const vec3 ui = shared::xyz(vi);
  const shared::ContactLaw* law_row = in.laws + std::size_t{in.material[i]} * p.material_count;
  std::conditional_t<kShifts, vec4, vec3> f(0.0f);
  // The force of particle j on i (zero unless they overlap), added in order.
  const bool by_impulse = shared::impulse_particle(p.flags, uint(i), p.rigid_particle_count);
  // Position contacts: both particles' contacts within reach (mass splitting).
  const float ni = kShifts ? shared::particle_shift_count(in.count[i], p.plane_count) : 0.0f;
  const auto add_contact = [&](uint j) {
    if (by_impulse && j < p.rigid_particle_count) return;
    // Two fluid particles: skipped before their loads (most of a liquid's list), as on Vulkan.
    if (kShifts && shared::shift_pair_skipped(uint(i), j, p.fluid_first, p.fluid_count)) return;
    const vec4 pj = in.pos[j];
    const vec4 vj = in.vel[j];
    if constexpr (kShifts) {
      // A rigid body's particle gathers the reactions of its contacts with other kinds'.
      const float nj = shared::particle_shift_count(in.count[j], p.plane_count);
      if (i < p.rigid_particle_count) {
        f += shared::rigid_contact_reaction(
            xi, ui, pi.w, ni, shared::xyz(pj), shared::xyz(vj), pj.w, vj.w, nj,
            in.laws[std::size_t{in.material[j]} * p.material_count + in.material[i]],
            p.gravity_dt.w);
      } else {
        f += shared::particle_contact_shift(
            xi, ui, pi.w, vi.w, ni, shared::xyz(pj), shared::xyz(vj), pj.w,
            shared::shift_partner_inverse_mass(j, p.rigid_particle_count, vj.w), nj,
            law_row[in.material[j]], p.gravity_dt.w);
      }
    } else {
      f += shared::particle_contact_force(xi, ui, pi.w, vi.w, shared::xyz(pj), shared::xyz(vj),
                                          pj.w, vj.w, law_row[in.material[j]], p.flags);
    }
  };
  const uint c = in.count[i];
  if (c <= p.neighbour_capacity) {
    const std::size_t stride = p.particle_count;
    for (uint k = 0; k < c; ++k) add_contact(in.list[std::size_t{k} * stride + i]);
  } else {
    const uint body_i = in.body[i];
    shared::grid_walk(p, in.ref[i], in.cell_start, [&](uint lo, uint hi) {
      for (uint t = lo; t < hi; ++t) {
        const uint j = in.order[t];
        if (!shared::contact_skipped(body_i, in.sbody[t], uint(i), j, exclusions, p.particle_count,
                                     p.linked_first)) {
          add_contact(j);
        }
      }
    });
  }
  for (uint k = 0; k < (by_impulse ? 0u : p.plane_count); ++k) {
    const shared::PlaneData pl = in.planes[k];
    if constexpr (kShifts) {
      f += shared::plane_contact_shift(xi, ui, pi.w, ni, pl.normal_offset, law_row[pl.material],
                                       p.gravity_dt.w);
    } else {
      f += shared::plane_contact_force(xi, ui, pi.w, vi.w, pl.normal_offset, law_row[pl.material],
                                       p.flags);
    }
  }
  if constexpr (kShifts) {
    force[i] = f;
  } else {
    force[i] = vec4(f, 0.0f);
  }
}

}  // namespace

void CudaDevice::launch_contacts_compute(const shared::StepParams& p) {
  if (p.particle_count == 0) return;
  const auto kernel = (p.flags & MOTES_FLAG_POSITION) != 0u ? contacts_compute_kernel<true>
                                                            : contacts_compute_kernel<false>;
  kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(
      p, contact_inputs(), buf<uint>(Buffer::LinkExclusions), buf<vec4>(Buffer::ParticleForce));
}

}  // namespace motes::cuda
