// particles_check: the motion guard's reduction (shared/motion_check.h) in four launches: a reset,
// the largest rate bits and the first non-finite particle (a warp reduction, then one atomicMax
// and one atomicMin per warp), the first particle with that rate, and its |v|^2. Max and min of
// integers: the result does not depend on the order the warps arrive in.
#include "cuda_device.h"
#include "shared/motion_check.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__device__ uint warp_max(uint v) {
  for (int o = 16; o > 0; o >>= 1) v = max(v, __shfl_xor_sync(0xFFFFFFFFu, v, o));
  return v;
}

__device__ uint warp_min(uint v) {
  for (int o = 16; o > 0; o >>= 1) v = min(v, __shfl_xor_sync(0xFFFFFFFFu, v, o));
  return v;
}

__global__ void particles_check_reset(uint* __restrict__ out) {
  out[MOTES_MOTION_RATE2] = 0u;
  out[MOTES_MOTION_FASTEST] = MOTES_MOTION_NONE;
  out[MOTES_MOTION_NON_FINITE] = MOTES_MOTION_NONE;
  out[MOTES_MOTION_SPEED2] = 0u;
}

__global__ void particles_check_reduce(shared::StepParams p, const vec4* __restrict__ pos,
                                       const vec4* __restrict__ vel, uint* __restrict__ out) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  uint rate2 = 0u;
  uint non_finite = MOTES_MOTION_NONE;
  if (i < p.particle_count) {
    const vec4 x = pos[i];
    const vec4 v = vel[i];
    if (shared::motion_finite(x, v)) {
      rate2 = shared::motion_rate2_bits(x, v);
    } else {
      non_finite = static_cast<uint>(i);
    }
  }
  rate2 = warp_max(rate2);
  non_finite = warp_min(non_finite);
  if ((threadIdx.x & 31u) == 0u) {
    if (rate2 != 0u) atomicMax(&out[MOTES_MOTION_RATE2], rate2);
    if (non_finite != MOTES_MOTION_NONE) atomicMin(&out[MOTES_MOTION_NON_FINITE], non_finite);
  }
}

__global__ void particles_check_fastest(shared::StepParams p, const vec4* __restrict__ pos,
                                        const vec4* __restrict__ vel, uint* __restrict__ out) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  const uint want = out[MOTES_MOTION_RATE2];
  uint fastest = MOTES_MOTION_NONE;
  if (i < p.particle_count) {
    const vec4 x = pos[i];
    const vec4 v = vel[i];
    if (shared::motion_finite(x, v) && shared::motion_rate2_bits(x, v) == want) {
      fastest = static_cast<uint>(i);
    }
  }
  fastest = warp_min(fastest);
  if ((threadIdx.x & 31u) == 0u && fastest != MOTES_MOTION_NONE) {
    atomicMin(&out[MOTES_MOTION_FASTEST], fastest);
  }
}

__global__ void particles_check_speed(const vec4* __restrict__ vel, uint* __restrict__ out) {
  const uint i = out[MOTES_MOTION_FASTEST];
  if (i != MOTES_MOTION_NONE)
    out[MOTES_MOTION_SPEED2] = shared::float_bits(shared::motion_speed2(vel[i]));
}

}  // namespace

void CudaDevice::launch_particles_check(const shared::StepParams& p) {
  uint* out = buf<uint>(Buffer::MotionCheck);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  particles_check_reset<<<1, 1, 0, stream_>>>(out);
  if (p.particle_count > 0) {
    particles_check_reduce<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(p, pos, vel, out);
    particles_check_fastest<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(p, pos, vel, out);
    particles_check_speed<<<1, 1, 0, stream_>>>(vel, out);
  }
}

}  // namespace motes::cuda
