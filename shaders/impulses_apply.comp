#version 450
// impulses_apply: each dynamic body (one thread per body) sums its particles' impulses, counts and
// moments in the contract's order (shared/impulse.h, MOTES_BODY_CHUNK) and applies them
// (shared/impulse.h: body_apply_impulse); with MOTES_FLAG_IMPULSE_COUNT it first keeps its
// velocities and contact count as the start of the impulse stage (and, with
// MOTES_FLAG_POSITION_GRAM, its contact Gram bound: shared/contact_gram.h); with
// MOTES_FLAG_IMPULSE_PUSH it keeps the velocities it leaves in BodyVelPush and BodyAngMomPush. As
// backends/openmp/impulses_apply.cpp. Bodies of args.x particles or more (0: none) are
// impulses_apply_wide.comp's (the same sums, a workgroup per body).
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY  // writes no particle position, velocity, grid or list
#include "kernel_common.glsl"
#include "shared/neighbours.h"
#include "impulses_apply_body.glsl"

void main() {
  uint b = thread_index();
  if (b >= p.body_count) return;
  // A body of args.x particles or more is impulses_apply_wide.comp's (args.x 0: none is).
  if (args.x != 0u && body_first[b + 1u] - body_first[b] >= args.x) return;
  vec4 com = body_pos[b];
  bool gram = (p.flags & MOTES_FLAG_POSITION_GRAM) != 0u;
  vec4 sum = vec4(0.0f);
  vec3 m = vec3(0.0f);
  float bound = 0.0f;
  if (com.w != 0.0f) {
    uint end = body_first[b + 1u];
    for (uint c = body_first[b]; c < end; c += MOTES_BODY_CHUNK) {
      vec4 part;
      vec3 part_m;
      chunk_sums(c, min(c + MOTES_BODY_CHUNK, end), part, part_m);
      sum = sum + part;
      m += part_m;
    }
    if (gram) {
      ContactGram g = gram_zero();
      for (uint c = body_first[b]; c < end; c += MOTES_BODY_CHUNK) {
        gram_merge(g, chunk_gram(c, min(c + MOTES_BODY_CHUNK, end), com));
      }
      bound = gram_bound(g, com, body_quat[b], body_inv_inertia[b]);
    }
  }
  stamp_body(b, com, 0u, 1u);
  finish_body(b, com, sum, m, gram, bound);
}
