#version 450
// grid_build, pass 2 of 5 (once per level): exclusive scan, in place, of each block of SCAN_BLOCK
// values, and each block's total into the next level. Level 0 is GridCellStart (T + 1 counts, the
// last one 0, so the scan leaves N there); higher levels live in the scan scratch buffer.
//   args.x: 0 = data in GridCellStart, 1 = data in scan_scratch at offset args.y
//   args.z: number of values;  args.w: offset of the block totals in scan_scratch
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

shared uint partial[WORKGROUP_SIZE];

uint load_value(uint i) { return args.x == 0u ? grid_cell_start[i] : scan_scratch[args.y + i]; }

void store_value(uint i, uint v) {
  if (args.x == 0u) {
    grid_cell_start[i] = v;
  } else {
    scan_scratch[args.y + i] = v;
  }
}

void main() {
  uint group = flat_group();
  uint count = args.z;
  if (group * uint(SCAN_BLOCK) >= count) return;  // whole workgroup: a padding group of a 2D grid
  uint lid = gl_LocalInvocationID.x;
  uint base = group * uint(SCAN_BLOCK) + lid * 4u;
  uint v[4];
  uint sum = 0u;
  for (uint k = 0u; k < 4u; ++k) {
    v[k] = base + k < count ? load_value(base + k) : 0u;
    sum += v[k];
  }
  partial[lid] = sum;
  barrier();
  // Inclusive Hillis-Steele scan of the per-thread sums.
  for (uint offset = 1u; offset < uint(WORKGROUP_SIZE); offset <<= 1u) {
    uint add = lid >= offset ? partial[lid - offset] : 0u;
    barrier();
    partial[lid] += add;
    barrier();
  }
  uint running = partial[lid] - sum;
  for (uint k = 0u; k < 4u; ++k) {
    if (base + k < count) store_value(base + k, running);
    running += v[k];
  }
  if (lid == uint(WORKGROUP_SIZE) - 1u) scan_scratch[args.w + group] = partial[lid];
}
