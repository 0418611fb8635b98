#version 450
// grid_build_scan_block on devices with subgroup arithmetic (chosen at device creation; the plain
// grid_build_scan_block.comp is the fallback): the same exclusive block scan, with the workgroup's
// per-thread sums scanned by subgroupExclusiveAdd within each subgroup and the subgroup totals
// scanned by the first subgroup. Works for any subgroup size (8 on lavapipe, 32 on NVIDIA, 64 on
// AMD) and for partial subgroups. Same args as grid_build_scan_block.comp.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "kernel_common.glsl"

shared uint subgroup_total[WORKGROUP_SIZE + 1];

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
  uint within = subgroupExclusiveAdd(sum);
  uint total = subgroupAdd(sum);
  if (subgroupElect()) subgroup_total[gl_SubgroupID] = total;
  barrier();
  // The first subgroup turns the subgroup totals into exclusive offsets, as many at a time as it
  // has active invocations (counted, so that a partial subgroup works too).
  if (gl_SubgroupID == 0u) {
    uint lanes = subgroupAdd(1u);
    uint lane = subgroupExclusiveAdd(1u);
    uint carry = 0u;
    for (uint first = 0u; first < gl_NumSubgroups; first += lanes) {
      uint i = first + lane;
      uint t = i < gl_NumSubgroups ? subgroup_total[i] : 0u;
      uint offset = carry + subgroupExclusiveAdd(t);
      if (i < gl_NumSubgroups) subgroup_total[i] = offset;
      carry += subgroupAdd(t);
    }
    if (subgroupElect()) subgroup_total[gl_NumSubgroups] = carry;
  }
  barrier();
  uint running = subgroup_total[gl_SubgroupID] + within;
  for (uint k = 0u; k < 4u; ++k) {
    if (base + k < count) store_value(base + k, running);
    running += v[k];
  }
  if (lid == 0u) scan_scratch[args.w + group] = subgroup_total[gl_NumSubgroups];
}
