// particles_integrate: semi-implicit Euler on the free spheres [Nr, N) (shared/body_math.h), or
// with MOTES_FLAG_PARTICLE_SHIFT the mean of their contacts' shifts (shared/particle_shift.h), one
// thread per particle, and a neighbour-list rebuild asked for when one has moved too far since
// the last build (one store per block at most).
#include "cuda_device.h"
#include "shared/body_math.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "shared/particle_shift.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void particles_integrate_kernel(shared::StepParams p, vec4* __restrict__ pos,
                                           vec4* __restrict__ vel, const vec4* __restrict__ force,
                                           const vec4* __restrict__ ref, uint* __restrict__ state) {
  const std::uint64_t i =
      p.rigid_particle_count + std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  bool moved = false;
  if (i < p.particle_count) {
    vec4 x = pos[i];
    vec4 v = vel[i];
    if ((p.flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {
      shared::particle_shift_apply(x, v, force[i], p.gravity_dt.w);
    } else {
      v = shared::linked_damped(v, static_cast<uint>(i), p.linked_first, p.linked_damping);
      shared::particle_integrate(x, v, force[i], p.gravity_dt, p.flags);
    }
    pos[i] = x;
    vel[i] = v;
    moved = shared::neighbour_moved_too_far(x, ref[i], p.neighbour_skin);
  }
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace

void CudaDevice::launch_particles_integrate(const shared::StepParams& p) {
  if (p.particle_count <= p.rigid_particle_count) return;
  particles_integrate_kernel<<<blocks_for(p.particle_count - p.rigid_particle_count), kBlock, 0,
                               stream_>>>(
      p, buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<vec4>(Buffer::ParticleForce), buf<vec4>(Buffer::NeighbourRefPos),
      buf<uint>(Buffer::NeighbourState));
}

}  // namespace motes::cuda
