// particles_update: particle positions and velocities follow their body's pose.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void particles_update_kernel(shared::uint n, BodyBuffers d) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (i < n) {
    const auto k = static_cast<shared::uint>(i);
    particle_update(d, k, d.particle_body[k]);
  }
}

}  // namespace

void CudaDevice::launch_particles_update(const shared::StepParams& p) {
  if (p.particle_count == 0) return;
  particles_update_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(p.particle_count,
                                                                                body_buffers());
}

}  // namespace motes::cuda
