// constraints_relax: every sweep over every colour of ConstraintColours in one block, each colour
// as constraints_solve projects it (its constraints strided over the block's threads), the block
// synchronised between colours (__syncthreads makes the colour's global writes visible to the
// block); with MOTES_FLAG_SKIN_CHECK the last sweep asks for a rebuild when a particle it moved
// is too far from where the lists were built.
#include "cuda_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

/// One block of this many threads: a 25 x 25 cloth's colours (about 300 constraints) take one
/// pass each.
constexpr int kRelaxBlock = 1024;

__global__ void __launch_bounds__(kRelaxBlock)
    constraints_relax_kernel(shared::StepParams p,
                             const shared::Constraint* __restrict__ constraints,
                             const uint* __restrict__ colours, vec4* pos, vec4* vel,
                             const vec4* __restrict__ ref, uint* __restrict__ state) {
  const float inv_dt = 1.0f / p.gravity_dt.w;
  bool moved = false;
  for (uint sweep = 0; sweep < p.constraint_sweeps; ++sweep) {
    const bool check = (p.flags & MOTES_FLAG_SKIN_CHECK) != 0 && sweep + 1 == p.constraint_sweeps;
    for (uint colour = 0; colour < p.constraint_count; ++colour) {
      const uint end = colours[colour + 1];
      for (uint k = colours[colour] + threadIdx.x; k < end; k += kRelaxBlock) {
        const shared::Constraint c = constraints[k];
        vec4 xa = pos[c.a];
        vec4 xb = pos[c.b];
        vec4 va = vel[c.a];
        vec4 vb = vel[c.b];
        shared::constraint_project(xa, xb, va, vb, c, inv_dt);
        pos[c.a] = xa;
        pos[c.b] = xb;
        vel[c.a] = va;
        vel[c.b] = vb;
        moved =
            moved || (check && (shared::neighbour_moved_too_far(xa, ref[c.a], p.neighbour_skin) ||
                                shared::neighbour_moved_too_far(xb, ref[c.b], p.neighbour_skin)));
      }
      __syncthreads();
    }
  }
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace

void CudaDevice::launch_constraints_relax(const shared::StepParams& p) {
  if (p.constraint_count == 0 || p.constraint_sweeps == 0) return;
  constraints_relax_kernel<<<1, kRelaxBlock, 0, stream_>>>(
      p, buf<shared::Constraint>(Buffer::Constraints), buf<uint>(Buffer::ConstraintColours),
      buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<vec4>(Buffer::NeighbourRefPos), buf<uint>(Buffer::NeighbourState));
}

}  // namespace motes::cuda
