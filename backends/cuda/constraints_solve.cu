// constraints_solve: one colour of distance constraints (no two share a particle), one thread per
// constraint (shared/links.h), and with MOTES_FLAG_SKIN_CHECK (the last sweep) a neighbour-list
// rebuild asked for when a particle it moved is too far from where the lists were built (one
// store per block at most).
#include "cuda_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void constraints_solve_kernel(shared::StepParams p,
                                         const shared::Constraint* __restrict__ constraints,
                                         vec4* __restrict__ pos, vec4* __restrict__ vel,
                                         const vec4* __restrict__ ref, uint* __restrict__ state) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  bool moved = false;
  if (k < p.constraint_count) {
    const shared::Constraint c = constraints[p.constraint_first + k];
    vec4 xa = pos[c.a];
    vec4 xb = pos[c.b];
    vec4 va = vel[c.a];
    vec4 vb = vel[c.b];
    shared::constraint_project(xa, xb, va, vb, c, 1.0f / p.gravity_dt.w);
    pos[c.a] = xa;
    pos[c.b] = xb;
    vel[c.a] = va;
    vel[c.b] = vb;
    moved = (p.flags & MOTES_FLAG_SKIN_CHECK) != 0 &&
            (shared::neighbour_moved_too_far(xa, ref[c.a], p.neighbour_skin) ||
             shared::neighbour_moved_too_far(xb, ref[c.b], p.neighbour_skin));
  }
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace

void CudaDevice::launch_constraints_solve(const shared::StepParams& p) {
  if (p.constraint_count == 0) return;
  constraints_solve_kernel<<<blocks_for(p.constraint_count), kBlock, 0, stream_>>>(
      p, buf<shared::Constraint>(Buffer::Constraints), buf<vec4>(Buffer::ParticlePos),
      buf<vec4>(Buffer::ParticleVel), buf<vec4>(Buffer::NeighbourRefPos),
      buf<uint>(Buffer::NeighbourState));
}

}  // namespace motes::cuda
