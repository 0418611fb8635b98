// halo_unpack: HaloData's entries scattered to the particles and rigid bodies HaloIndex names
// (shared/halo.h), a grid-stride loop; a neighbour-list rebuild is asked for when a particle it
// wrote is too far from its NeighbourRefPos (one store per block at most).
#include "cuda_device.h"
#include "halo_buffers.h"
#include "halo_entries.cuh"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void halo_unpack_kernel(shared::StepParams p, const uint* __restrict__ index,
                                   const vec4* __restrict__ data, const vec4* __restrict__ ref,
                                   vec4* __restrict__ pos, vec4* __restrict__ vel,
                                   HaloBodies bodies, uint* __restrict__ state) {
  bool moved = false;
  // An entry that names no particle or body writes nothing.
  halo_entries(
      p, index,
      [&](std::uint64_t t, uint i) {
        const vec4 x = data[MOTES_HALO_PARTICLE_VEC4S * t];
        pos[i] = x;
        vel[i] = data[MOTES_HALO_PARTICLE_VEC4S * t + 1];
        moved |= shared::neighbour_moved_too_far(x, ref[i], p.neighbour_skin);
      },
      [&](std::uint64_t at, uint i) {
        const vec4* in = data + at;
        for (uint c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) bodies.state[c][i] = in[c];
      });
  // Every thread of the block reaches this (no early return above).
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace

void CudaDevice::launch_halo_unpack(const shared::StepParams& p) {
  const std::uint64_t total = std::uint64_t{p.halo_particles} + p.halo_bodies;
  if (total == 0) return;
  halo_unpack_kernel<<<grid_stride_blocks(total), kBlock, 0, stream_>>>(
      p, buf<uint>(Buffer::HaloIndex), buf<vec4>(Buffer::HaloData),
      buf<vec4>(Buffer::NeighbourRefPos), buf<vec4>(Buffer::ParticlePos),
      buf<vec4>(Buffer::ParticleVel), halo_bodies(), buf<uint>(Buffer::NeighbourState));
}

}  // namespace motes::cuda
