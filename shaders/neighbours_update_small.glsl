// The whole of neighbours_update_small.comp and neighbours_update_small_subgroup.comp, whose scan
// MOTES_SMALL_SUBGROUP_SCAN chooses.
//
// neighbours_update for small grids (a pass of the neighbours_update family, one workgroup): when
// NeighbourState asks for a rebuild, this workgroup builds the whole grid itself (the six passes
// of grid_build_*.comp as phases separated by workgroup barriers, with their steps from
// grid_build.glsl: clear, count, exclusive scan, scatter, canonical placement; the same
// GridCellStart and the same stable order by (bucket, particle id)) and starts the list build; it
// writes the gate word args.x of IndirectArgs (1: build, 0: not), which neighbours_build,
// dispatched directly after it, reads before anything else. A step without a rebuild then costs
// two dispatches (this one and the gated build, which ends at once) instead of
// neighbours_update.comp's ten indirect ones and their barriers. Used while the table has at most
// small_rebuild_table_ buckets (backends/vulkan/neighbours_update.cpp).
//
// One workgroup's build is bound by latency and by its one memory path: every particle's count,
// scatter and placement is a chain of dependent loads, and accesses to many lines at once are
// taken a line at a time. So the workgroup is as large as the device allows (its size is
// specialization constant 0, up to 1,024 invocations), each invocation keeps FLIGHT particles'
// loads in flight before it uses any of them, and the scan reads the counts side by side where
// the device has subgroups.
#ifndef MOTES_NEIGHBOURS_UPDATE_SMALL_GLSL
#define MOTES_NEIGHBOURS_UPDATE_SMALL_GLSL
#define MOTES_LOCAL_SIZE_SPECIALIZED
// Its invocations read buckets, bucket starts and slots that others of the workgroup wrote (after
// phase()).
#define MOTES_GRID_COHERENT
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "shared/neighbours.h"
#include "grid_build.glsl"
#include "neighbours_start.glsl"

#define FLIGHT 4u

shared bool rebuild_now;
shared uint sums[gl_WorkGroupSize.x];

// Makes this workgroup's buffer writes visible to its own later reads (with the buffers read
// across invocations declared coherent: MOTES_GRID_COHERENT).
void phase() {
  memoryBarrierBuffer();
  barrier();
}

// The exclusive scan of GridCellStart's first `values` counts, in place.
#ifdef MOTES_SMALL_SUBGROUP_SCAN
// Each subgroup owns a contiguous range, which its lanes read side by side (FLIGHT rows of the
// subgroup's width at a time): the subgroups' totals are scanned by the first invocation, then each
// subgroup walks its range again with subgroupInclusiveAdd. The width and each lane's place are
// counted over the active invocations, as in grid_build_scan_block_subgroup.comp, so that a
// partial subgroup works too.
void small_scan(uint lid, uint threads, uint values) {
  uint width = subgroupAdd(1u);
  uint lane = subgroupExclusiveAdd(1u);
  uint groups = gl_NumSubgroups;
  uint per = (values + groups - 1u) / groups;
  uint lo = min(gl_SubgroupID * per, values);
  uint hi = min(lo + per, values);
  uint own = 0u;
  for (uint b = lo + lane; b < hi; b += width) own += grid_cell_start[b];
  own = subgroupAdd(own);
  if (subgroupElect()) sums[gl_SubgroupID] = own;
  barrier();
  if (lid == 0u) {
    uint total = 0u;
    for (uint g = 0u; g < groups; ++g) {
      uint v = sums[g];
      sums[g] = total;
      total += v;
    }
  }
  barrier();
  uint running = sums[gl_SubgroupID];
  for (uint b0 = lo; b0 < hi; b0 += width * FLIGHT) {
    uint count[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint b = b0 + k * width + lane;
      count[k] = b < hi ? grid_cell_start[b] : 0u;
    }
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint b = b0 + k * width + lane;
      uint through = subgroupInclusiveAdd(count[k]);
      if (b < hi) grid_cell_start[b] = running + through - count[k];
      running += subgroupAdd(count[k]);
    }
  }
}
#else
// Each invocation sums a contiguous segment, the segments' sums are scanned in shared memory,
// then each invocation writes its segment's starts. Its reads are a line per invocation, which
// one workgroup's memory path takes one at a time: the subgroup version above is several times
// faster (docs/benchmarks.md).
void small_scan(uint lid, uint threads, uint values) {
  uint segment = (values + threads - 1u) / threads;
  uint lo = min(lid * segment, values);
  uint hi = min(lo + segment, values);
  uint own = 0u;
  for (uint b = lo; b < hi; ++b) own += grid_cell_start[b];
  sums[lid] = own;
  barrier();
  for (uint d = 1u; d < threads; d <<= 1u) {
    uint before = lid >= d ? sums[lid - d] : 0u;
    barrier();
    sums[lid] += before;
    barrier();
  }
  uint running = sums[lid] - own;
  for (uint b = lo; b < hi; ++b) {
    uint count = grid_cell_start[b];
    grid_cell_start[b] = running;
    running += count;
  }
}
#endif

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint threads = gl_WorkGroupSize.x;
  if (lid == 0u) rebuild_now = neighbour_state[MOTES_NEIGHBOUR_REBUILD] != 0u;
  barrier();
  bool rebuild = rebuild_now;
  if (lid == 0u) indirect_args[args.x] = rebuild ? 1u : 0u;
  if (!rebuild) return;  // the whole workgroup

  uint n = p.particle_count;
  uint stride = threads * FLIGHT;
  // grid_build_clear: GridCellStart's T + 1 values.
  uint values = p.table_mask + 2u;
  for (uint b = lid; b < values; b += threads) grid_cell_start[b] = 0u;
  phase();
  // grid_build_count, FLIGHT particles at a time: positions, then buckets and atomics, then stores.
  // Indices past the end load the last particle and write nothing.
  for (uint i0 = lid; i0 < n; i0 += stride) {
    vec4 x[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) x[k] = particle_pos[min(i0 + k * threads, n - 1u)];
    uint b[FLIGHT];
    uint rank[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) {
      b[k] = grid_build_bucket(x[k]);
      if (i0 + k * threads < n) rank[k] = atomicAdd(grid_cell_start[b[k]], 1u);
    }
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint i = i0 + k * threads;
      if (i < n) {
        grid_bucket_of[i] = b[k];
        grid_arrival[i] = rank[k];
      }
    }
  }
  phase();
  small_scan(lid, threads, values);
  phase();
  // grid_build_scatter, FLIGHT particles at a time.
  for (uint i0 = lid; i0 < n; i0 += stride) {
    uint b[FLIGHT];
    uint rank[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint i = min(i0 + k * threads, n - 1u);
      b[k] = grid_bucket_of[i];
      rank[k] = grid_arrival[i];
    }
    uint start[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) start[k] = grid_cell_start[b[k]];
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint i = i0 + k * threads;
      if (i < n) grid_unsorted[start[k] + rank[k]] = i;
    }
  }
  phase();
  // grid_build_place, FLIGHT particles at a time: bucket, range, the range's first entry and the
  // particle's data are loaded for all of them before any slot is counted.
  for (uint i0 = lid; i0 < n; i0 += stride) {
    uint b[FLIGHT];
    vec4 x[FLIGHT];
    uint body[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint i = min(i0 + k * threads, n - 1u);
      b[k] = grid_bucket_of[i];
      x[k] = particle_pos[i];
      body[k] = particle_body[i];
    }
    uint first_slot[FLIGHT];
    uint end_slot[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) {
      first_slot[k] = grid_cell_start[b[k]];
      end_slot[k] = grid_cell_start[b[k] + 1u];
    }
    uint first[FLIGHT];
    for (uint k = 0u; k < FLIGHT; ++k) first[k] = grid_unsorted[first_slot[k]];
    for (uint k = 0u; k < FLIGHT; ++k) {
      uint i = i0 + k * threads;
      if (i < n) {
        grid_build_copy(i, grid_build_slot(i, first_slot[k], end_slot[k], first[k]), x[k],
                        body[k]);
      }
    }
  }
  if (lid == 0u) neighbours_start();
}

#endif  // MOTES_NEIGHBOURS_UPDATE_SMALL_GLSL
