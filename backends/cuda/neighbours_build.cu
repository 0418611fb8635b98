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

/// The warps' staging of candidates (neighbours_build_kernel): a row's sorted slots a chunk at a
/// time, each slot's particle, body and position.
constexpr uint kWarpSize = 32;
constexpr uint kWarps = CudaDevice::kBlock / kWarpSize;
constexpr uint kStageSlots = 64;
struct StagedSlots {
  uint order[kWarps][kStageSlots];
  uint body[kWarps][kStageSlots];
  float4 pos[kWarps][kStageSlots];  // vec4's constructor is not allowed in shared memory
};

__device__ uint warp_min(uint v) {
  for (int d = 16; d > 0; d /= 2) v = min(v, __shfl_xor_sync(0xffffffffu, v, d));
  return v;
}
__device__ uint warp_max(uint v) {
  for (int d = 16; d > 0; d /= 2) v = max(v, __shfl_xor_sync(0xffffffffu, v, d));
  return v;
}

/// A thread per particle, in particle order or in grid order (`grid_order`). Each list is the same
/// whichever thread builds it, and its entries come in the order of shared::grid_walk: the rows
/// (dz, dy) in turn, a row whose three buckets are one range (shared::grid_row_whole) from its
/// first slot to its last, the others bucket by bucket. A warp walks its rows together: for row r
/// it takes the span from the lowest first slot of its threads' whole rows r to the highest last
/// one and, when that span is at most `stage_span` slots, loads it into shared memory a chunk of
/// kStageSlots at a time, coalesced, each candidate once for the warp; each thread then reads its
/// own range's part of the chunk. Threads in grid order are neighbours in the grid, so their rows
/// overlap; a wider span (threads in particle order far apart, a warp across the end of a grid
/// row) is walked by each thread from global memory, as are rows walked bucket by bucket.
/// stage_span 0: every row from global memory.
__global__ void neighbours_build_kernel(shared::StepParams p, BuildInputs in, BuildOutputs out,
                                        bool grid_order, uint stage_span) {
  __shared__ uint block_over;
  __shared__ uint block_most;
  __shared__ StagedSlots staged;
  if (threadIdx.x == 0) {
    block_over = 0;
    block_most = 0;
  }
  __syncthreads();
  const uint warp = threadIdx.x / kWarpSize;
  const uint lane = threadIdx.x % kWarpSize;
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  const bool present = k < p.particle_count;
  const uint i = !present ? 0u : grid_order ? in.order[k] : static_cast<uint>(k);
  const vec4 pi = present ? in.pos[i] : vec4{0.0f, 0.0f, 0.0f, 0.0f};
  if (present) out.ref[i] = pi;
  // Static particles never move and get no force: no list (they still help their warp stage).
  const bool walks = present && in.vel[i].w != 0.0f;
  const uint body_i = walks ? in.body[i] : 0u;
  // Impulse contacts: a particle whose slots were valid under the last build keeps them when its
  // list comes out as it was; only its old list is read back (the others' entries are written
  // blind; measured on an H200, that saved 5% of the dam break's build and nothing of W1's:
  // docs/benchmarks.md, "The list build's threads and traffic").
  const uint built = out.state[MOTES_NEIGHBOUR_BUILDS] - 1u;  // neighbours_begin counted this
  const bool tracked =
      walks && out.stamp != nullptr && i < p.rigid_particle_count && out.stamp[i] == built;
  const uint old_count = tracked ? out.count[i] : 0u;
  bool same = true;
  const float support_i = shared::neighbour_fluid_support(pi, i, p.fluid_first, p.fluid_count);
  const std::size_t stride = p.particle_count;
  uint c = 0;
  const auto consider = [&](uint j, uint body_j, vec4 pj) {
    if (shared::contact_skipped(body_i, body_j, i, j, in.exclusions, p.particle_count,
                                p.linked_first) ||
        !shared::neighbour_within(
            pi, pj, p.neighbour_skin,
            shared::max(support_i,
                        shared::neighbour_fluid_support(pj, j, p.fluid_first, p.fluid_count)))) {
      return;
    }
    if (c < p.neighbour_capacity) {
      uint& entry = out.list[std::size_t{c} * stride + i];
      if (tracked && same) same = entry == j;  // read only while it can still match
      entry = j;
    }
    ++c;
  };
  const auto consider_slots = [&](uint lo, uint hi) {
    for (uint t = lo; t < hi; ++t) consider(in.order[t], in.sbody[t], in.spos[t]);
  };
  const uint mask = p.table_mask;
  const int cx = shared::grid_cell_coord(pi.x, p.inv_cell_size);
  const int cy = shared::grid_cell_coord(pi.y, p.inv_cell_size);
  const int cz = shared::grid_cell_coord(pi.z, p.inv_cell_size);
  uint centres[9];
  for (int row = 0; row < 9; ++row) {
    const uint cb = shared::grid_bucket(cx, cy + row % 3 - 1, cz + row / 3 - 1, mask);
    centres[row] = cb;
    const bool whole = walks && shared::grid_row_whole(centres, row, mask);
    const uint lo = whole ? in.cell_start[cb - 1u] : 0xffffffffu;
    const uint hi = whole ? in.cell_start[cb + 2u] : 0u;
    const uint first = warp_min(lo);
    const uint last = warp_max(hi);
    if (last > first && last - first <= stage_span) {  // the same in every thread of the warp
      for (uint base = first; base < last; base += kStageSlots) {
        const uint n = min(kStageSlots, last - base);
        __syncwarp();
        for (uint s = lane; s < n; s += kWarpSize) {
          staged.order[warp][s] = in.order[base + s];
          staged.body[warp][s] = in.sbody[base + s];
          const vec4 q = in.spos[base + s];
          staged.pos[warp][s] = make_float4(q.x, q.y, q.z, q.w);
        }
        __syncwarp();
        const uint end = min(hi, base + n);
        for (uint t = max(lo, base); t < end; ++t) {
          const float4 q = staged.pos[warp][t - base];
          consider(staged.order[warp][t - base], staged.body[warp][t - base],
                   vec4(q.x, q.y, q.z, q.w));
        }
      }
    } else if (whole) {
      consider_slots(lo, hi);
    }
    if (walks && !whole) {
      for (uint b3 = 0; b3 < 3u; ++b3) {
        const uint b = (cb + b3 - 1u) & mask;
        if (!shared::grid_bucket_seen(centres, row, b, mask)) {
          consider_slots(in.cell_start[b], in.cell_start[b + 1u]);
        }
      }
    }
  }
  if (tracked && shared::neighbour_keeps_slots(old_count, c, same, p.neighbour_capacity)) {
    out.stamp[i] = built + 1u;
  }
  if (present) {
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
  const bool grid_order = list_order_ == ListOrder::Grid ||
                          (list_order_ == ListOrder::Auto && p.fluid_count != 0u);
  neighbours_build_kernel<<<blocks_for(p.particle_count), kBlock, 0, stream_>>>(
      p, in, out, grid_order, list_stage_span_);
}

}  // namespace motes::cuda
