#version 450
// neighbours_update for small grids (a pass of the neighbours_update family, one workgroup): when
// NeighbourState asks for a rebuild, this workgroup builds the whole grid itself (the six passes
// of grid_build_*.comp as phases separated by workgroup barriers, with their steps from
// grid_build.glsl: clear, count, exclusive scan, scatter, canonical placement; the same
// GridCellStart and the same stable order by (bucket, particle id)) and starts the list build; it writes the gate word args.x of IndirectArgs (1: build,
// 0: not), which neighbours_build, dispatched directly after it, reads before anything else. A
// step without a rebuild then costs two dispatches (this one and the gated build, which ends at
// once) instead of neighbours_update.comp's ten indirect ones and their barriers. Used while the
// table has at most MOTES_VULKAN_SMALL_REBUILD buckets (backends/vulkan/neighbours_update.cpp; by
// default never: one workgroup's build is latency-bound, about 200 us at 16,384 particles on an
// H200, so it pays only where builds are rarer than one in about 20 steps; docs/benchmarks.md).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "shared/neighbours.h"
#include "grid_build.glsl"
#include "neighbours_start.glsl"

shared bool rebuild_now;
shared uint sums[WORKGROUP_SIZE];

// Makes this workgroup's buffer writes visible to its own later reads.
void phase() {
  memoryBarrierBuffer();
  barrier();
}

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint threads = uint(WORKGROUP_SIZE);
  if (lid == 0u) rebuild_now = neighbour_state[MOTES_NEIGHBOUR_REBUILD] != 0u;
  barrier();
  bool rebuild = rebuild_now;
  if (lid == 0u) indirect_args[args.x] = rebuild ? 1u : 0u;
  if (!rebuild) return;  // the whole workgroup

  // grid_build_clear: GridCellStart's T + 1 values.
  uint values = p.table_mask + 2u;
  for (uint b = lid; b < values; b += threads) grid_cell_start[b] = 0u;
  phase();
  // grid_build_count: each particle's bucket and arrival rank within it.
  for (uint i = lid; i < p.particle_count; i += threads) grid_build_count(i);
  phase();
  // The exclusive scan of the counts: each invocation sums a segment, the segments' sums are
  // scanned in shared memory, then each invocation writes its segment's starts.
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
    uint n = grid_cell_start[b];
    grid_cell_start[b] = running;
    running += n;
  }
  phase();
  // grid_build_scatter: by arrival rank.
  for (uint i = lid; i < p.particle_count; i += threads) grid_build_scatter(i);
  phase();
  // grid_build: each particle at its canonical slot (its rank by id within its bucket).
  for (uint i = lid; i < p.particle_count; i += threads) grid_build_place(i);
  if (lid == 0u) neighbours_start();
}
