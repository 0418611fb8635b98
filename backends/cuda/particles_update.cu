// particles_update: the rigid particles' [0, Nr) positions and velocities follow their body's
// pose; a neighbour-list rebuild is asked for when one has moved too far since the last build.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void particles_update_kernel(shared::uint n, float skin, BodyBuffers d) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  bool moved = false;
  if (i < n) {
    const auto k = static_cast<shared::uint>(i);
    moved = particle_update(d, k, d.particle_body[k], skin);
  }
  ask_rebuild_if(d, moved);
}

}  // namespace

void CudaDevice::launch_particles_update(const shared::StepParams& p) {
  if (p.rigid_particle_count == 0) return;
  particles_update_kernel<<<blocks_for(p.rigid_particle_count), kBlock, 0, stream_>>>(
      p.rigid_particle_count, p.neighbour_skin, body_buffers());
}

}  // namespace motes::cuda
