// neighbours_build: every dynamic particle's list of the particles of other bodies closer than
// r_i + r_j + skin (shared/neighbours.h), in the canonical order of the 27-cell walk, its first K
// entries kept (entry k at k * N + i) and its full count written; as
// backends/openmp/neighbours_build.cpp. Two launches: one thread starts the build in
// NeighbourState, then a thread per particle (in particle order, or in grid order when the scene
// has fluid); the build's figures are reduced per block and added with integer atomics.
#include "cuda_device.h"
#include "shared/grid_walk.h"
#include "shared/impulse.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void neighbours_begin_kernel(uint* __restrict__ state) {
  state[MOTES_NEIGHBOUR_REBUILD] = 0;
  state[MOTES_NEIGHBOUR_BUILDS] += 1;
  state[MOTES_NEIGHBOUR_OVER_CAPACITY] = 0;
  state[MOTES_NEIGHBOUR_MAX_COUNT] = 0;
}

struct BuildInputs {
  const vec4* __restrict__ pos;
  const vec4* __restrict__ vel;
  const uint* __restrict__ body;
  const uint* __restrict__ order;
  const uint* __restrict__ cell_start;
  const vec4* __restrict__ spos;
  const uint* __restrict__ sbody;
  const uint* __restrict__ exclusions;  ///< LinkExclusions (shared/links.h)
};

struct BuildOutputs {
  uint* __restrict__ list;
  uint* __restrict__ count;
  vec4* __restrict__ ref;
  uint* __restrict__ state;
  uint* __restrict__ stamp;  ///< ImpulseStamp (impulse contacts; else null)
};

__global__ void neighbours_build_kernel(shared::StepParams p, BuildInputs in, BuildOutputs out) {
  __shared__ uint block_over;
  __shared__ uint block_most;
  if (threadIdx.x == 0) {
    block_over = 0;
    block_most = 0;
  }
  __syncthreads();
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k < p.particle_count) {
    // Each list is the same whichever thread builds it; the order is for the memory. Without
    // fluid, threads in particle order: bodies, cloths and ropes are built body by body and keep
    // their particles together, so a warp's particles are neighbours in space and its list
    // entries (k * N + i) are written side by side (W1's dense pile on an H200: the build 20%
    // faster than in grid order at 4 M spheres, 4% at 16.8 M). Fluid particles mix as they
    // flow: threads in grid order, whose warp shares its cells' candidates (the dam break over
    // a second: 7% faster so).
    const uint i = p.fluid_count == 0u ? static_cast<uint>(k) : in.order[k];
    const vec4 pi = in.pos[i];
    out.ref[i] = pi;
    uint c = 0;
    if (in.vel[i].w != 0.0f) {  // static particles never move and get no force
      const uint body_i = in.body[i];
      // Impulse contacts: a particle whose slots were valid under the last build keeps them when
      // its list comes out as it was; only its old list is read back (the others' entries are
      // written blind; measured on an H200, that saved 5% of the dam break's build and nothing of
      // W1's: docs/benchmarks.md, "The list build's threads and traffic").
      const uint built = out.state[MOTES_NEIGHBOUR_BUILDS] - 1u;  // neighbours_begin counted this
      const bool tracked =
          out.stamp != nullptr && i < p.rigid_particle_count && out.stamp[i] == built;
      const uint old_count = tracked ? out.count[i] : 0u;
      bool same = true;
      const float support_i = shared::neighbour_fluid_support(pi, i, p.fluid_first, p.fluid_count);
      const std::size_t stride = p.particle_count;
      shared::grid_walk(p, pi, in.cell_start, [&](uint lo, uint hi) {
        for (uint t = lo; t < hi; ++t) {
          const uint j = in.order[t];
          if (shared::contact_skipped(body_i, in.sbody[t], i, j, in.exclusions, p.particle_count,
                                      p.linked_first) ||
              !shared::neighbour_within(
                  pi, in.spos[t], p.neighbour_skin,
                  shared::max(support_i, shared::neighbour_fluid_support(
                                             in.spos[t], j, p.fluid_first, p.fluid_count)))) {
            continue;
          }
          if (c < p.neighbour_capacity) {
            uint& entry = out.list[std::size_t{c} * stride + i];
            if (tracked && same) same = entry == j;  // read only while it can still match
            entry = j;
          }
          ++c;
        }
      });
      if (tracked && shared::neighbour_keeps_slots(old_count, c, same, p.neighbour_capacity)) {
        out.stamp[i] = built + 1u;
      }
    }
    out.count[i] = c;
    if (c > p.neighbour_capacity) atomicAdd(&block_over, 1u);
    if (c > 0) atomicMax(&block_most, c);
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    if (block_over != 0) atomicAdd(&out.state[MOTES_NEIGHBOUR_OVER_CAPACITY], block_over);
    if (block_most != 0) atomicMax(&out.state[MOTES_NEIGHBOUR_MAX_COUNT], block_most);
  }
}

}  // namespace

void CudaDevice::launch_neighbours_build(const shared::StepParams& p) {
  uint* state = buf<uint>(Buffer::NeighbourState);
  neighbours_begin_kernel<<<1, 1, 0, stream_>>>(state);
  if (p.particle_count == 0) return;
  const BuildInputs in{buf<vec4>(Buffer::ParticlePos),   buf<vec4>(Buffer::ParticleVel),
                       buf<uint>(Buffer::ParticleBody),  buf<uint>(Buffer::GridOrder),
                       buf<uint>(Buffer::GridCellStart), buf<vec4>(Buffer::SortedPos),
                       buf<uint>(Buffer::SortedBody),    buf<uint>(Buffer::LinkExclusions)};
  const BuildOutputs out{buf<uint>(Buffer::NeighbourList), buf<uint>(Buffer::NeighbourCount),
                         buf<vec4>(Buffer::NeighbourRefPos), state,
                         (p.flags & MOTES_FLAG_IMPULSE) != 0u && sizes_.impulse != 0
                             ? buf<uint>(Buffer::ImpulseStamp)
                             : nullptr};
  neighbours_build_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(p, in, out);
}

}  // namespace motes::cuda
