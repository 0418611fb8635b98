// bodies_reduce: force and torque of each body (one thread per body), summed over its particles in
// particle order, as backends/openmp/bodies_reduce.cpp. A block's bodies own one contiguous span
// of particles; the block stages it through shared memory a tile at a time with coalesced loads,
// and each thread adds its own particles of the tile in order: the same sums as a thread reading
// its particles straight from memory (body_passes.cuh: body_reduce), without the strided reads
// that made 15-particle dominoes run at a fraction of the memory bandwidth.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

constexpr shared::uint kTile = 512;  // particles staged at a time: 16 KiB of shared memory

/// vec4 has constructors, which __shared__ arrays may not: the tiles hold float4 (same layout).
__device__ inline shared::vec4 from_float4(float4 v) { return {v.x, v.y, v.z, v.w}; }

__global__ void bodies_reduce_kernel(shared::uint bodies, BodyBuffers d) {
  __shared__ float4 tile_pos[kTile];
  __shared__ float4 tile_force[kTile];
  const auto* pos = reinterpret_cast<const float4*>(d.pos);
  const auto* force = reinterpret_cast<const float4*>(d.force);
  const std::uint64_t b0 = std::uint64_t{blockIdx.x} * blockDim.x;
  if (b0 >= bodies) return;  // the whole block
  const std::uint64_t b = b0 + threadIdx.x;
  const bool mine = b < bodies;
  const std::uint64_t b_end = min(b0 + blockDim.x, std::uint64_t{bodies});
  const shared::uint span_lo = d.first[b0];
  const shared::uint span_hi = d.first[b_end];
  const shared::vec4 com = mine ? d.body_pos[b] : shared::vec4(0.0f);
  const bool dynamic = mine && com.w != 0.0f;
  const shared::uint lo = mine ? d.first[b] : 0u;
  const shared::uint hi = mine ? d.first[b + 1] : 0u;
  shared::vec3 f(0.0f);
  shared::vec3 tau(0.0f);
  for (shared::uint c = span_lo; c < span_hi; c += kTile) {
    const shared::uint c_end = min(c + kTile, span_hi);
    for (shared::uint k = threadIdx.x; c + k < c_end; k += blockDim.x) {
      tile_pos[k] = pos[c + k];
      tile_force[k] = force[c + k];
    }
    __syncthreads();
    if (dynamic) {
      for (shared::uint i = max(lo, c); i < min(hi, c_end); ++i) {
        body_reduce_add(f, tau, from_float4(tile_pos[i - c]), com, from_float4(tile_force[i - c]));
      }
    }
    __syncthreads();
  }
  if (mine) {
    d.body_force[b] = shared::vec4(f, 0.0f);
    d.body_torque[b] = shared::vec4(tau, 0.0f);
  }
}

}  // namespace

void CudaDevice::launch_bodies_reduce(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  bodies_reduce_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p.body_count,
                                                                         body_buffers());
}

}  // namespace motes::cuda
