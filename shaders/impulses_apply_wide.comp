#version 450
// impulses_apply for bodies of args.x particles or more (backends/vulkan/impulses_apply.cpp): a
// workgroup per body. Its first WIDE_LANES threads sum WIDE_LANES chunks of the body's particles
// side by side (shared/impulse.h, MOTES_BODY_CHUNK), thread 0 adds the chunks' sums in chunk
// order: impulses_apply.comp's order, and bits, without one thread adding a rigid bunny's 3,000
// particles in turn.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY  // writes no particle position, velocity, grid or list
#include "kernel_common.glsl"
#include "shared/neighbours.h"
#include "impulses_apply_body.glsl"

// Threads that sum chunks (the rest of the workgroup only stamps): their Gram matrices fit in
// 16 KiB of shared memory with the sums, the least Vulkan guarantees.
#define WIDE_LANES 64u

shared vec4 s_part[WIDE_LANES];
shared vec4 s_part_m[WIDE_LANES];
shared float s_gram[WIDE_LANES * 36u];

void main() {
  uint b = flat_group();
  if (b >= p.body_count) return;  // the whole workgroup: padding of a 2D grid
  // Bodies of fewer than args.x particles are impulses_apply.comp's (the whole workgroup).
  if (body_first[b + 1u] - body_first[b] < args.x) return;
  uint lane = gl_LocalInvocationID.x;
  vec4 com = body_pos[b];
  bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  vec4 sum = vec4(0.0f);
  vec3 m = vec3(0.0f);
  float bound = 0.0f;
  if (com.w != 0.0f) {  // the same for the whole workgroup
    uint first = body_first[b];
    uint end = body_first[b + 1u];
    uint round_size = WIDE_LANES * MOTES_BODY_CHUNK;
    for (uint r = first; r < end; r += round_size) {
      if (lane < WIDE_LANES) {
        uint c = r + lane * MOTES_BODY_CHUNK;
        vec4 part;
        vec3 part_m;
        chunk_sums(min(c, end), min(c + MOTES_BODY_CHUNK, end), part, part_m);
        s_part[lane] = part;
        s_part_m[lane] = vec4(part_m, 0.0f);
      }
      barrier();
      if (lane == 0u) {
        uint chunks = (min(r + round_size, end) - r + MOTES_BODY_CHUNK - 1u) / MOTES_BODY_CHUNK;
        for (uint k = 0u; k < chunks; ++k) {
          sum = sum + s_part[k];
          m += xyz(s_part_m[k]);
        }
      }
      barrier();
    }
    if (gram) {
      ContactGram g = gram_zero();
      for (uint r = first; r < end; r += round_size) {
        if (lane < WIDE_LANES) {
          uint c = r + lane * MOTES_BODY_CHUNK;
          ContactGram part = chunk_gram(min(c, end), min(c + MOTES_BODY_CHUNK, end), com);
          for (uint e = 0u; e < 36u; ++e) s_gram[e * WIDE_LANES + lane] = part.k[e];
        }
        barrier();
        if (lane == 0u) {
          uint chunks = (min(r + round_size, end) - r + MOTES_BODY_CHUNK - 1u) / MOTES_BODY_CHUNK;
          for (uint k = 0u; k < chunks; ++k) {
            for (uint e = 0u; e < 36u; ++e) g.k[e] += s_gram[e * WIDE_LANES + k];
          }
        }
        barrier();
      }
      if (lane == 0u) bound = gram_bound(g, com, body_quat[b], body_inv_inertia[b]);
    }
  }
  stamp_body(b, com, lane, uint(WORKGROUP_SIZE));
  if (lane == 0u) finish_body(b, com, sum, m, gram, bound);
}
