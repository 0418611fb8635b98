// halo_pack: the state a neighbour rank holds copies of, gathered into HaloData (shared/halo.h):
// a grid-stride loop over the particle entries, then the rigid body entries. Plain copies of
// whole vec4s, so the bits are those of every other backend.
#include "cuda_device.h"
#include "halo_buffers.h"
#include "halo_entries.cuh"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void halo_pack_kernel(shared::StepParams p, const uint* __restrict__ index,
                                 const vec4* __restrict__ pos, const vec4* __restrict__ vel,
                                 HaloBodies bodies, vec4* __restrict__ data) {
  // An entry that names no particle or body is left as it is.
  halo_entries(
      p, index,
      [&](std::uint64_t t, uint i) {
        data[MOTES_HALO_PARTICLE_VEC4S * t] = pos[i];
        data[MOTES_HALO_PARTICLE_VEC4S * t + 1] = vel[i];
      },
      [&](std::uint64_t at, uint i) {
        vec4* out = data + at;
        for (uint c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) out[c] = bodies.state[c][i];
      });
}

}  // namespace

void CudaDevice::launch_halo_pack(const shared::StepParams& p) {
  const std::uint64_t total = std::uint64_t{p.halo_particles} + p.halo_bodies;
  if (total == 0) return;
  halo_pack_kernel<<<grid_stride_blocks(total), kBlock, 0, stream_>>>(
      p, buf<uint>(Buffer::HaloIndex), buf<vec4>(Buffer::ParticlePos),
      buf<vec4>(Buffer::ParticleVel), halo_bodies(), buf<vec4>(Buffer::HaloData));
}

}  // namespace motes::cuda
