// impulses_apply: each dynamic body sums its particles' impulses, counts and moments in the
// contract's order (shared/impulse.h, MOTES_BODY_CHUNK: chunks of 64 particles, then the chunks)
// and applies them (shared/impulse.h: body_apply_impulse); with MOTES_FLAG_IMPULSE_COUNT it first
// keeps its velocities and contact count as the start of the impulse stage (and, with
// MOTES_FLAG_POSITION_GRAM, its contact Gram bound: shared/contact_gram.h); with
// MOTES_FLAG_IMPULSE_PUSH it keeps the velocities it leaves in BodyVelPush and BodyAngMomPush. As
// backends/openmp/impulses_apply.cpp. One thread per body; a body of kWideBodyParticles or more
// particles a block instead, whose threads sum its chunks side by side (a rigid bunny's 3,000
// particles were 3,000 additions in turn on one thread, 80 times a frame). A block per body for
// every body made the million-particle scene's 10,838 dice of 64 slower (36 to 50 ms a frame on an
// H200): one chunk each, summed by one thread of 64 all the same.
#include "cuda_device.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

__device__ inline vec4 from_float4(float4 v) { return {v.x, v.y, v.z, v.w}; }

/// Threads of a body's block in the wide kernel.
constexpr unsigned kWideThreads = 64;

struct ApplyBuffers {
  const uint* __restrict__ first;
  vec4* __restrict__ com;   // BodyPos (moved by the projection of position contacts)
  vec4* __restrict__ quat;  // BodyQuat
  const vec4* __restrict__ inv_inertia;
  const vec4* __restrict__ impulse;
  const vec4* __restrict__ moment;
  vec4* __restrict__ vel;
  vec4* __restrict__ angmom;
  vec4* __restrict__ angvel;
  vec4* __restrict__ vel0;
  vec4* __restrict__ angvel0;
  vec4* __restrict__ vel_push;     // BodyVelPush (written with MOTES_FLAG_IMPULSE_PUSH)
  vec4* __restrict__ angmom_push;  // BodyAngMomPush
  uint* __restrict__ stamp;        // ImpulseStamp (written by the counting pass)
  const uint* __restrict__ state;  // NeighbourState
  const vec4* __restrict__ pos;    // ParticlePos (read with MOTES_FLAG_POSITION_GRAM)
};

/// Everything after the sums (both kernels): the counting pass's start and Gram bound (`bound`,
/// in the Gram counting pass), the body's update, the pushed velocities.
__device__ void finish_body(const shared::StepParams& p, const ApplyBuffers& d, uint b, vec4 com,
                            vec4 sum, vec3 m, bool gram, float bound) {
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) != 0u) {
    d.vel0[b] = shared::impulse_start_velocity(d.vel[b], d.vel0[b], sum.w, p.flags);
    d.angvel0[b] = shared::impulse_start_angular_velocity(d.angvel[b], d.angvel0[b], p.flags);
    if (gram) d.angvel0[b].w = bound;
  }
  vec4 vel = d.vel[b];
  vec4 angmom = d.angmom[b];
  vec4 angvel;
  vec4 quat = d.quat[b];
  shared::body_apply_contacts(com, quat, d.inv_inertia[b], vel, angmom, angvel, shared::xyz(sum), m,
                              p.gravity_dt, p.flags);
  d.com[b] = com;
  d.quat[b] = quat;
  d.vel[b] = vel;
  d.angmom[b] = angmom;
  d.angvel[b] = angvel;
  if ((p.flags & MOTES_FLAG_IMPULSE_PUSH) != 0u) {
    d.vel_push[b] = vel;
    d.angmom_push[b] = angmom;
  }
}

/// The counting pass has read every slot: the body's particles' slots are now this build's.
__device__ void stamp_body(const shared::StepParams& p, const ApplyBuffers& d, uint b, vec4 com,
                           uint lane, uint lanes) {
  if ((p.flags & MOTES_FLAG_IMPULSE_COUNT) == 0u || com.w == 0.0f) return;
  const uint builds = d.state[MOTES_NEIGHBOUR_BUILDS];
  const uint end = d.first[b + 1];
  for (uint i = d.first[b] + lane; i < end; i += lanes) d.stamp[i] = builds;
}

/// One chunk's sums (shared/impulse.h, MOTES_BODY_CHUNK): particles [c, end) in order from zero.
__device__ void chunk_sums(const ApplyBuffers& d, uint c, uint end, vec4& part, vec3& part_m) {
  part = vec4(0.0f);
  part_m = vec3(0.0f);
#pragma unroll 4
  for (uint i = c; i < end; ++i) {
    part = part + d.impulse[i];
    part_m += shared::xyz(d.moment[i]);
  }
}

/// One chunk's Gram matrix (shared/contact_gram.h), in the same order.
__device__ shared::ContactGram chunk_gram(const ApplyBuffers& d, uint c, uint end, vec4 com) {
  shared::ContactGram g = shared::gram_zero();
  for (uint i = c; i < end; ++i) {
    shared::gram_add(g, d.impulse[i], d.moment[i], shared::xyz(d.pos[i]) - shared::xyz(com));
  }
  return g;
}

/// Particles of body b.
__device__ uint body_size(const ApplyBuffers& d, uint b) { return d.first[b + 1] - d.first[b]; }

/// A thread per body, for the bodies of fewer than `wide_from` particles (the others are the wide
/// kernel's).
__global__ void impulses_apply_kernel(shared::StepParams p, ApplyBuffers d, uint wide_from) {
  const std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (t >= p.body_count) return;
  const auto b = static_cast<uint>(t);
  if (body_size(d, b) >= wide_from) return;
  const vec4 com = d.com[b];
  const bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  vec4 sum(0.0f);
  vec3 m(0.0f);
  float bound = 0.0f;
  if (com.w != 0.0f) {
    const uint end = d.first[b + 1];
    for (uint c = d.first[b]; c < end; c += MOTES_BODY_CHUNK) {
      vec4 part;
      vec3 part_m;
      chunk_sums(d, c, min(c + MOTES_BODY_CHUNK, end), part, part_m);
      sum = sum + part;
      m += part_m;
    }
    if (gram) {
      shared::ContactGram g = shared::gram_zero();
      for (uint c = d.first[b]; c < end; c += MOTES_BODY_CHUNK) {
        shared::gram_merge(g, chunk_gram(d, c, min(c + MOTES_BODY_CHUNK, end), com));
      }
      bound = shared::gram_bound(g, com, d.quat[b], d.inv_inertia[b]);
    }
  }
  stamp_body(p, d, b, com, 0, 1);
  finish_body(p, d, b, com, sum, m, gram, bound);
}

/// A block per body of `wide_from` particles or more (the others are the thread kernel's): its
/// threads sum kWideThreads chunks side by side, then thread 0 adds the chunks' sums in chunk order
/// (the contract's order: the thread kernel's bits).
__global__ void __launch_bounds__(kWideThreads)
    impulses_apply_wide_kernel(shared::StepParams p, ApplyBuffers d, uint wide_from) {
  // vec4 has constructors, which __shared__ arrays may not: float4 (the same layout).
  __shared__ float4 parts[kWideThreads];
  __shared__ float4 parts_m[kWideThreads];
  __shared__ float grams[kWideThreads * 36];
  const uint b = blockIdx.x;
  if (body_size(d, b) < wide_from) return;  // the whole block
  const uint lane = threadIdx.x;
  const vec4 com = d.com[b];
  const bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  vec4 sum(0.0f);
  vec3 m(0.0f);
  float bound = 0.0f;
  if (com.w != 0.0f) {  // the same for the whole block
    const uint first = d.first[b];
    const uint end = d.first[b + 1];
    const uint round = kWideThreads * MOTES_BODY_CHUNK;
    for (uint r = first; r < end; r += round) {
      const uint c = r + lane * MOTES_BODY_CHUNK;  // this thread's chunk: [c, c + CHUNK)
      vec4 part;
      vec3 part_m;
      chunk_sums(d, min(c, end), min(c + MOTES_BODY_CHUNK, end), part, part_m);
      parts[lane] = make_float4(part.x, part.y, part.z, part.w);
      parts_m[lane] = make_float4(part_m.x, part_m.y, part_m.z, 0.0f);
      __syncthreads();
      if (lane == 0) {
        const uint chunks = (min(r + round, end) - r + MOTES_BODY_CHUNK - 1) / MOTES_BODY_CHUNK;
        for (uint k = 0; k < chunks; ++k) {
          sum = sum + from_float4(parts[k]);
          m += shared::xyz(from_float4(parts_m[k]));
        }
      }
      __syncthreads();
    }
    if (gram) {
      shared::ContactGram g = shared::gram_zero();
      for (uint r = first; r < end; r += round) {
        const uint c = r + lane * MOTES_BODY_CHUNK;
        const shared::ContactGram part =
            chunk_gram(d, min(c, end), min(c + MOTES_BODY_CHUNK, end), com);
        for (int e = 0; e < 36; ++e) grams[e * kWideThreads + lane] = part.k[e];
        __syncthreads();
        if (lane == 0) {
          const uint chunks = (min(r + round, end) - r + MOTES_BODY_CHUNK - 1) / MOTES_BODY_CHUNK;
          for (uint k = 0; k < chunks; ++k) {
            for (int e = 0; e < 36; ++e) g.k[e] += grams[e * kWideThreads + k];
          }
        }
        __syncthreads();
      }
      if (lane == 0) bound = shared::gram_bound(g, com, d.quat[b], d.inv_inertia[b]);
    }
  }
  stamp_body(p, d, b, com, lane, kWideThreads);
  if (lane == 0) finish_body(p, d, b, com, sum, m, gram, bound);
}

}  // namespace

void CudaDevice::launch_impulses_apply(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  const ApplyBuffers d{buf<uint>(Buffer::BodyFirst),       buf<vec4>(Buffer::BodyPos),
                       buf<vec4>(Buffer::BodyQuat),        buf<vec4>(Buffer::BodyInvInertia),
                       buf<vec4>(Buffer::ParticleForce),   buf<vec4>(Buffer::ParticleMoment),
                       buf<vec4>(Buffer::BodyVel),         buf<vec4>(Buffer::BodyAngMom),
                       buf<vec4>(Buffer::BodyAngVel),      buf<vec4>(Buffer::BodyVelStart),
                       buf<vec4>(Buffer::BodyAngVelStart), buf<vec4>(Buffer::BodyVelPush),
                       buf<vec4>(Buffer::BodyAngMomPush),  buf<uint>(Buffer::ImpulseStamp),
                       buf<uint>(Buffer::NeighbourState),  buf<vec4>(Buffer::ParticlePos)};
  // Large bodies a block each, the others a thread each; with BodyFirst not known, a thread each.
  const uint wide_from = largest_body_ >= kWideBodyParticles ? kWideBodyParticles : ~uint{0};
  if (smallest_body_ < wide_from) {
    impulses_apply_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p, d, wide_from);
  }
  if (wide_from != ~uint{0}) {
    impulses_apply_wide_kernel<<<p.body_count, kWideThreads, 0, stream_>>>(p, d, wide_from);
  }
}

}  // namespace motes::cuda
