// particles_update: the rigid particles' [0, Nr) positions and velocities follow their body's
// pose; a neighbour-list rebuild is asked for when one has moved too far since the last build.
// With MOTES_FLAG_ABSORB each first hands what the constraints did to it to its body
// (shared/body_math.h: particle_handed_impulse, and its moment). As
// backends/openmp/particles_update.cpp and shaders/particles_update.comp.
#include "body_passes.cuh"
#include "cuda_device.h"

namespace motes::cuda {

namespace {

__global__ void particles_update_kernel(shared::uint n, float skin, shared::uint flags,
                                        BodyBuffers d, shared::vec4* __restrict__ impulse,
                                        shared::vec4* __restrict__ moment) {
  const std::uint64_t i = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  bool moved = false;
  if (i < n) {
    const auto k = static_cast<shared::uint>(i);
    const shared::uint b = d.particle_body[k];
    if (impulse != nullptr) {  // MOTES_FLAG_ABSORB
      const shared::vec4 q = d.quat[b];
      const shared::vec3 j = shared::particle_handed_impulse(
          d.vel[k], q, d.body_vel[b], d.angvel[b], d.local[k], impulse[k], flags);
      impulse[k] = shared::vec4(j, 0.0f);
      moment[k] =
          shared::vec4(shared::cross(shared::quat_rotate(q, shared::xyz(d.local[k])), j), 0.0f);
    }
    moved = particle_update(d, k, b, skin);
  }
  ask_rebuild_if(d, moved);
}

}  // namespace

void CudaDevice::launch_particles_update(const shared::StepParams& p) {
  if (p.rigid_particle_count == 0) return;
  const bool absorb = (p.flags & MOTES_FLAG_ABSORB) != 0u;
  particles_update_kernel<<<blocks_for(p.rigid_particle_count), kBlock, 0, stream_>>>(
      p.rigid_particle_count, p.neighbour_skin, p.flags, body_buffers(),
      absorb ? buf<shared::vec4>(Buffer::ParticleForce) : nullptr,
      absorb ? buf<shared::vec4>(Buffer::ParticleMoment) : nullptr);
}

}  // namespace motes::cuda
