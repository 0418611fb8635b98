// bodies_step: bodies_reduce, bodies_integrate and particles_update fused into one pass, one
// thread per body, for scenes whose bodies are small (a free sphere, a 15-particle domino). It
// saves two launches and the round trips of the body force, torque and pose through memory; the
// arithmetic is that of the three kernels (body_passes.cuh). CudaDevice::launch chooses it when
// the three calls follow each other and every body owns exactly its BodyFirst range.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void bodies_step_kernel(shared::StepParams p, BodyBuffers d) {
  const std::uint64_t t = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  bool moved = false;
  if (t < p.body_count) {
    const auto b = static_cast<shared::uint>(t);
    body_reduce(d, b);
    body_step(d, b, p.gravity_dt, p.flags);
    const shared::uint end = d.first[b + 1];
    for (shared::uint i = d.first[b]; i < end; ++i) {
      moved = particle_update(d, i, b, p.neighbour_skin) || moved;
    }
  }
  ask_rebuild_if(d, moved);
}

}  // namespace

void CudaDevice::launch_bodies_step(const shared::StepParams& p) {
  if (p.body_count == 0) return;
  bodies_step_kernel<<<blocks_for(p.body_count), kBlock, 0, stream_>>>(p, body_buffers());
}

}  // namespace motes::cuda
