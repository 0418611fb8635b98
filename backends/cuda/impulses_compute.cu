// impulses_compute: every dynamic rigid particle (one thread per particle id) sums the impulses of
// its contacts with the rigid particles of its list, in list order (a particle with more
// neighbours than its list holds walks the grid of the last build instead: the same pairs in the
// same order), then the planes, and writes only its own impulse, count and moment
// (shared/impulse.h). Each pair is evaluated lower id first, so the two particles of a contact get
// bitwise opposite impulses; each keeps the contact's accumulated impulse in its own slot of
// ContactImpulse (valid while ImpulseStamp matches the lists' build; a correcting sweep of split
// impulses, MOTES_FLAG_IMPULSE_SPLIT, in ContactImpulseSplit, which the last relaxing sweep,
// MOTES_FLAG_IMPULSE_PUSH, fills too). As backends/openmp/impulses_compute.cpp and
// shaders/impulses_compute.comp.
//
// The counting pass of impulse contacts also lists the particles within reach of a contact (a
// contact within reach lists both of its particles; a particle beyond its list's capacity is
// listed whatever it touches), and the sweeps that follow it in its substep visit only those, a
// thread each (CudaDevice::sweep_follows_count): the others' results are the zeros that pass
// wrote (kernels.h). Standing dominoes touch the floor with their bottom row only: W2's sweeps
// visit a fifth of its particles.
#include "cuda_device.h"
#include "shared/grid_walk.h"
#include "shared/impulse.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

/// impulses_compute's inputs: those of every contact, and the bodies' state.
struct ImpulseInputs : ContactInputs {
  const vec4* __restrict__ local;
  const vec4* __restrict__ com;
  const vec4* __restrict__ quat;
  const vec4* __restrict__ inv_inertia;
  const vec4* __restrict__ body_vel;
  const vec4* __restrict__ body_angvel;
  const vec4* __restrict__ vel0;
  const vec4* __restrict__ angvel0;
  const uint* __restrict__ state;
};

/// The state of body b that its contacts read.
__device__ shared::ImpulseBody impulse_body(const ImpulseInputs& in, uint b, uint flags) {
  return shared::impulse_body_of(in.com[b], in.quat[b], in.inv_inertia[b], in.body_vel[b],
                                 in.body_angvel[b], in.vel0[b], in.angvel0[b], flags);
}

/// Held to 3 blocks of kBlock threads an SM (at most 85 registers: it takes 80): left free it took
/// 145, one block an SM, 12% of the SM's warps, and waited on its loads; W2's 100,000 impulse
/// dominoes on an H200 3.79 -> 2.63 ms/step (2 blocks: 2.80; 4, 64 registers and spills: 3.18).
/// docs/benchmarks.md, "Registers and occupancy".
/// listed: [0] the count, then the particles within reach of a contact: filled by a counting pass
/// (from_list false), visited by a sweep (from_list true); nullptr: every particle, nothing listed.
__global__ void __launch_bounds__(CudaDevice::kBlock, CudaDevice::kImpulseBlocksPerSm)
    impulses_compute_kernel(shared::StepParams p, ImpulseInputs in, vec4* __restrict__ impulse,
                            vec4* __restrict__ moment, vec4* __restrict__ acc_main,
                            vec4* __restrict__ acc_split, const uint* __restrict__ stamp,
                            uint* __restrict__ listed, bool from_list) {
  const std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  uint i = 0;
  if (from_list) {
    if (t >= listed[0]) return;
    i = listed[1 + t];
  } else {
    if (t >= p.rigid_particle_count) return;
    i = static_cast<uint>(t);
  }
  if (in.vel[i].w == 0.0f) {  // static particle: its impulse is never used
    impulse[i] = vec4(0.0f);
    moment[i] = vec4(0.0f);
    return;
  }
  const float margin = shared::impulse_margin(p.neighbour_skin);
  const uint bi = in.body[i];
  const vec4 xi = shared::contact_particle(in.pos[i], in.quat[bi], in.local[i], p.flags);
  const shared::ImpulseBody own = impulse_body(in, bi, p.flags);
  const shared::ContactLaw* law_row = in.laws + std::size_t{in.material[i]} * p.material_count;
  const uint builds = in.state[MOTES_NEIGHBOUR_BUILDS];
  const bool counting = (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
  // A counting pass that lists: whether a contact of this particle is within reach.
  const bool lists = listed != nullptr && !from_list;
  bool touches = false;
  const uint own_stamp = stamp[i];
  const std::size_t nr = p.rigid_particle_count;
  // The accumulated impulses this pass reads and writes, and where it copies them.
  vec4* const acc = (p.flags & MOTES_FLAG_IMPULSE_SPLIT) != 0u ? acc_split : acc_main;
  vec4* const copy = (p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u ? acc_split : nullptr;
  vec4 sum(0.0f);
  vec3 moment_sum(0.0f);
  // The impulse of the contact with particle j (rigid particles only), added in order; its
  // accumulated impulse in slot `slot` (nullptr: none).
  const auto add_contact = [&](uint j, vec4* slot) {
    if (j >= p.rigid_particle_count) return;
    const uint bj = in.body[j];
    const vec4 xj = shared::contact_particle(in.pos[j], in.quat[bj], in.local[j], p.flags);
    const shared::ImpulseBody other = impulse_body(in, bj, p.flags);
    if (lists) {  // the test of pair_impulse, from the same numbers
      vec4 xa, xb;
      shared::pair_places(own.com, xi, other.com, xj, i < j, p.flags, xa, xb);
      touches = touches || shared::pair_within_reach(xa, xb, margin);
    }
    const bool valid =
        !counting || shared::impulse_slots_valid(own_stamp, stamp[j], in.vel[j].w, builds);
    vec4 a = slot != nullptr && valid ? *slot : vec4(0.0f);
    vec3 arm;
    const vec4 r = shared::pair_impulse(
        own, xi, other, xj, i < j, margin,
        in.laws[shared::pair_law_index(i, in.material[i], j, in.material[j], p.material_count)],
        p.gravity_dt, p.flags, a, arm);
    if (slot != nullptr) {
      *slot = a;
      if (copy != nullptr) copy[slot - acc] = a;
    }
    shared::impulse_add(sum, moment_sum, r, arm, p.flags);
  };
  const uint c = in.count[i];
  if (c <= p.neighbour_capacity) {
    const std::size_t stride = p.particle_count;
    for (uint k = 0; k < c; ++k) {
      const uint j = in.list[std::size_t{k} * stride + i];
      const bool slotted = j < p.rigid_particle_count &&
                           shared::impulse_pair_slotted(c, in.count[j], p.neighbour_capacity);
      add_contact(j, slotted ? acc + std::size_t{k} * nr + i : nullptr);
    }
  } else {
    touches = true;  // listed whatever it touches (as the openmp device lists it)
    shared::grid_walk(p, in.ref[i], in.cell_start, [&](uint lo, uint hi) {
      for (uint s = lo; s < hi; ++s) {
        if (!shared::contact_excluded(in.sbody[s], bi)) add_contact(in.order[s], nullptr);
      }
    });
  }
  for (uint k = 0; k < p.plane_count; ++k) {
    const shared::PlaneData pl = in.planes[k];
    const std::size_t at = (std::size_t{p.neighbour_capacity} + k) * nr + i;
    vec4& a = acc[at];
    if (lists) {  // the test of plane_contact_impulse, from the same numbers
      const vec4 no = shared::contact_plane(pl.normal_offset, own, p.flags);
      touches = touches || shared::dot(shared::xyz(no), shared::xyz(xi)) - no.w - xi.w < margin;
    }
    vec3 arm;
    const vec4 r = shared::plane_contact_impulse(
        own, xi, pl.normal_offset, margin, law_row[pl.material], p.gravity_dt, p.flags, a, arm);
    if (copy != nullptr) copy[at] = a;
    shared::impulse_add(sum, moment_sum, r, arm, p.flags);
  }
  impulse[i] = sum;
  moment[i] = vec4(moment_sum, 0.0f);
  if (lists) {  // appended a warp at a time (the order is free: each thread writes only its own)
    const unsigned lanes = __activemask();
    const unsigned hits = __ballot_sync(lanes, touches);
    if (hits == 0u) return;
    const int leader = __ffs(static_cast<int>(hits)) - 1;
    const unsigned lane = threadIdx.x & 31u;
    uint base = 0;
    if (static_cast<int>(lane) == leader) base = atomicAdd(listed, static_cast<uint>(__popc(hits)));
    base = __shfl_sync(lanes, base, leader);
    if (touches) listed[1 + base + static_cast<uint>(__popc(hits & ((1u << lane) - 1u)))] = i;
  }
}

}  // namespace

void CudaDevice::launch_impulses_compute(const shared::StepParams& p) {
  if (p.rigid_particle_count == 0) return;
  const ImpulseInputs in{contact_inputs(),
                         buf<vec4>(Buffer::ParticleLocal),
                         buf<vec4>(Buffer::BodyPos),
                         buf<vec4>(Buffer::BodyQuat),
                         buf<vec4>(Buffer::BodyInvInertia),
                         buf<vec4>(Buffer::BodyVel),
                         buf<vec4>(Buffer::BodyAngVel),
                         buf<vec4>(Buffer::BodyVelStart),
                         buf<vec4>(Buffer::BodyAngVelStart),
                         buf<uint>(Buffer::NeighbourState)};
  // A counting pass of impulse contacts lists the particles within reach, from one wave of
  // particles up (impulse_list_from_); a sweep that follows it in its substep (launch() decides:
  // sweep_follows_count, the same particle count) visits only those.
  const bool listing = impulse_listed_ != nullptr && p.rigid_particle_count >= impulse_list_from_;
  const bool lists = listing && (p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u &&
                     (p.flags & MOTES_FLAG_POSITION) == 0u;
  const bool from_list = listing && impulse_sweep_listed_;
  if (lists) cudaMemsetAsync(impulse_listed_, 0, sizeof(uint), stream_);
  impulses_compute_kernel<<<blocks_for(p.rigid_particle_count), kBlock, 0, stream_>>>(
      p, in, buf<vec4>(Buffer::ParticleForce), buf<vec4>(Buffer::ParticleMoment),
      buf<vec4>(Buffer::ContactImpulse), buf<vec4>(Buffer::ContactImpulseSplit),
      buf<uint>(Buffer::ImpulseStamp), lists || from_list ? impulse_listed_ : nullptr, from_list);
}

}  // namespace motes::cuda
