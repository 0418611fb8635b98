#version 450
// bodies_reduce: force and torque of each body (one thread per body), summed over its particles in
// particle order, as backends/openmp/bodies_reduce.cpp. A workgroup's bodies own one contiguous
// span of particles; the workgroup stages it through shared memory a tile at a time with
// coalesced loads, and each thread adds its own particles of the tile in order: the same sums as a
// thread reading its particles straight from memory, without strided reads (15-particle dominoes
// ran at a fraction of the memory bandwidth that way). As backends/cuda/bodies_reduce.cu.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY  // writes no particle position, velocity, grid or list
#include "kernel_common.glsl"
#include "shared/body_math.h"

#define TILE 256  // particles staged at a time: 8 KiB of shared memory

shared vec4 tile_pos[TILE];
shared vec4 tile_force[TILE];

void main() {
  uint b0 = flat_group() * uint(WORKGROUP_SIZE);
  if (b0 >= p.body_count) return;  // the whole workgroup (a padding group of a 2D grid too)
  uint b = b0 + gl_LocalInvocationID.x;
  bool mine = b < p.body_count;
  uint b_end = min(b0 + uint(WORKGROUP_SIZE), p.body_count);
  uint span_lo = body_first[b0];
  uint span_hi = body_first[b_end];
  vec4 com = mine ? body_pos[b] : vec4(0.0f);
  bool dynamic = mine && com.w != 0.0f;
  uint lo = mine ? body_first[b] : 0u;
  uint hi = mine ? body_first[b + 1u] : 0u;
  vec3 f = vec3(0.0f);
  vec3 tau = vec3(0.0f);
  for (uint c = span_lo; c < span_hi; c += uint(TILE)) {
    uint c_end = min(c + uint(TILE), span_hi);
    for (uint k = gl_LocalInvocationID.x; c + k < c_end; k += uint(WORKGROUP_SIZE)) {
      tile_pos[k] = particle_pos[c + k];
      tile_force[k] = particle_force[c + k];
    }
    barrier();
    if (dynamic) {
      for (uint i = max(lo, c); i < min(hi, c_end); ++i) {
        vec4 fi = tile_force[i - c];
        f += xyz(fi);
        tau += particle_torque(tile_pos[i - c], com, fi);
      }
    }
    barrier();
  }
  if (mine) {
    body_force[b] = vec4(f, 0.0f);
    body_torque[b] = vec4(tau, 0.0f);
  }
}
