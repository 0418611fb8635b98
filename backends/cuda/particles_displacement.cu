// particles_displacement: the largest squared distance a particle has moved since the ranks last
// partitioned the scene (shared/halo.h: displacement2_bits), in two launches: a reset, then a
// grid-stride reduction (a warp max, then one atomicMax per warp). An integer max of float bits:
// the result does not depend on the order the warps arrive in.
#include "cuda_device.h"
#include "shared/halo.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__device__ uint warp_max(uint v) {
  for (int o = 16; o > 0; o >>= 1) v = max(v, __shfl_xor_sync(0xFFFFFFFFu, v, o));
  return v;
}

__global__ void particles_displacement_reset(uint* __restrict__ out) {
  out[MOTES_PARTITION_DISPLACEMENT2] = 0u;
}

__global__ void particles_displacement_reduce(shared::StepParams p, const vec4* __restrict__ pos,
                                              const vec4* __restrict__ ref,
                                              uint* __restrict__ out) {
  const std::uint64_t n = p.particle_count;
  const std::uint64_t stride = std::uint64_t{gridDim.x} * blockDim.x;
  uint largest = 0u;
  for (std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x; i < n; i += stride) {
    largest = max(largest, shared::displacement2_bits(pos[i], ref[i]));
  }
  // Every thread of a warp reaches the shuffle (the loop has no early exit).
  largest = warp_max(largest);
  if ((threadIdx.x & 31u) == 0u && largest != 0u) {
    atomicMax(&out[MOTES_PARTITION_DISPLACEMENT2], largest);
  }
}

}  // namespace

void CudaDevice::launch_particles_displacement(const shared::StepParams& p) {
  uint* out = buf<uint>(Buffer::PartitionCheck);
  particles_displacement_reset<<<1, 1, 0, stream_>>>(out);
  if (p.particle_count == 0) return;
  particles_displacement_reduce<<<grid_stride_blocks(p.particle_count), kBlock, 0, stream_>>>(
      p, buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::PartitionRefPos), out);
}

}  // namespace motes::cuda
