// energy_reduce: the energy guard's reduction (shared/energy.h). One thread block of 256 threads
// per block of 256 items: each thread its item's energy into shared memory, then the tree of
// shared/energy.h (slot t += slot t + s, s = 128, ..., 1, a barrier between levels), and thread 0
// writes the block's four words. No atomics: the same sums in the same order on every run.
#include "cuda_device.h"
#include "shared/energy.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

static_assert(CudaDevice::kBlock == MOTES_ENERGY_BLOCK, "one thread per item of a block");

__global__ void energy_reduce_blocks(shared::StepParams p, const vec4* __restrict__ ppos,
                                     const vec4* __restrict__ pvel, const vec4* __restrict__ bpos,
                                     const vec4* __restrict__ bvel,
                                     const vec4* __restrict__ bangvel,
                                     const vec4* __restrict__ bangmom, uint* __restrict__ out) {
  __shared__ float kinetic[MOTES_ENERGY_BLOCK];
  __shared__ float potential[MOTES_ENERGY_BLOCK];
  __shared__ float largest[MOTES_ENERGY_BLOCK];
  __shared__ uint item[MOTES_ENERGY_BLOCK];
  const uint t = threadIdx.x;
  const uint bodies = p.body_count;
  const uint items = shared::energy_items(bodies, p.particle_count, p.rigid_particle_count);
  const std::uint64_t j64 = std::uint64_t{blockIdx.x} * MOTES_ENERGY_BLOCK + t;
  const vec3 ref(shared::bits_float(out[0]), shared::bits_float(out[1]),
                 shared::bits_float(out[2]));
  vec3 e(0.0f);
  if (j64 < bodies) {
    const auto j = static_cast<uint>(j64);
    e = shared::item_energy(bpos[j], bvel[j], bpos[j].w, true, bangvel[j], bangmom[j], p.gravity_dt,
                            ref);
  } else if (j64 < items) {
    const uint i = p.rigid_particle_count + (static_cast<uint>(j64) - bodies);
    e = shared::item_energy(ppos[i], pvel[i], pvel[i].w, false, vec4(0.0f), vec4(0.0f),
                            p.gravity_dt, ref);
  }
  const bool counts = e.z != 0.0f;
  kinetic[t] = e.x;
  potential[t] = e.y;
  largest[t] = counts ? e.x : MOTES_ENERGY_NO_KINETIC;
  item[t] = counts ? static_cast<uint>(j64) : MOTES_ENERGY_NONE;
  __syncthreads();
  for (uint s = MOTES_ENERGY_BLOCK / 2; s > 0; s >>= 1) {
    if (t < s) {
      kinetic[t] = kinetic[t] + kinetic[t + s];
      potential[t] = potential[t] + potential[t + s];
      if (shared::energy_larger(largest[t + s], item[t + s], largest[t], item[t])) {
        largest[t] = largest[t + s];
        item[t] = item[t + s];
      }
    }
    __syncthreads();
  }
  if (t == 0) {
    uint* block = out + MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS * std::uint64_t{blockIdx.x};
    block[MOTES_ENERGY_KINETIC] = shared::float_bits(kinetic[0]);
    block[MOTES_ENERGY_POTENTIAL] = shared::float_bits(potential[0]);
    block[MOTES_ENERGY_MAX_KINETIC] = shared::float_bits(largest[0]);
    block[MOTES_ENERGY_MAX_ITEM] = item[0];
  }
}

}  // namespace

void CudaDevice::launch_energy_reduce(const shared::StepParams& p) {
  const uint blocks = shared::energy_blocks(
      shared::energy_items(p.body_count, p.particle_count, p.rigid_particle_count));
  if (blocks == 0) return;
  energy_reduce_blocks<<<blocks, MOTES_ENERGY_BLOCK, 0, stream_>>>(
      p, buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel), buf<vec4>(Buffer::BodyPos),
      buf<vec4>(Buffer::BodyVel), buf<vec4>(Buffer::BodyAngVel), buf<vec4>(Buffer::BodyAngMom),
      buf<uint>(Buffer::EnergyPartials));
}

}  // namespace motes::cuda
