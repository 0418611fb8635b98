#version 450
// particles_check: the motion guard's reduction (shared/motion_check.h), pass args.x: a reset (one
// thread), the largest rate bits and the first non-finite particle (a workgroup reduction in
// shared memory, then one atomicMax and one atomicMin per workgroup), the first particle with that
// rate, and its |v|^2 (one thread). Max and min of integers: the result does not depend on the
// order the workgroups run in.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/motion_check.h"

shared uint group_rate2;
shared uint group_index;

void main() {
  uint pass = args.x;
  if (pass == MOTES_MOTION_PASS_RESET) {
    if (thread_index() == 0u) {
      motion_check[MOTES_MOTION_RATE2] = 0u;
      motion_check[MOTES_MOTION_FASTEST] = MOTES_MOTION_NONE;
      motion_check[MOTES_MOTION_NON_FINITE] = MOTES_MOTION_NONE;
      motion_check[MOTES_MOTION_SPEED2] = 0u;
    }
    return;
  }
  if (pass == MOTES_MOTION_PASS_SPEED) {
    uint f = motion_check[MOTES_MOTION_FASTEST];
    if (thread_index() == 0u && f != MOTES_MOTION_NONE) {
      motion_check[MOTES_MOTION_SPEED2] = float_bits(motion_speed2(particle_vel[f]));
    }
    return;
  }
  if (gl_LocalInvocationID.x == 0u) {
    group_rate2 = 0u;
    group_index = MOTES_MOTION_NONE;
  }
  barrier();
  uint i = thread_index();
  if (i < p.particle_count) {
    vec4 x = particle_pos[i];
    vec4 v = particle_vel[i];
    bool ok = motion_finite(x, v);
    if (pass == MOTES_MOTION_PASS_REDUCE) {
      if (ok) {
        atomicMax(group_rate2, motion_rate2_bits(x, v));
      } else {
        atomicMin(group_index, i);
      }
    } else if (ok && motion_rate2_bits(x, v) == motion_check[MOTES_MOTION_RATE2]) {
      atomicMin(group_index, i);
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u) {
    if (pass == MOTES_MOTION_PASS_REDUCE) {
      if (group_rate2 != 0u) atomicMax(motion_check[MOTES_MOTION_RATE2], group_rate2);
      if (group_index != MOTES_MOTION_NONE) {
        atomicMin(motion_check[MOTES_MOTION_NON_FINITE], group_index);
      }
    } else if (group_index != MOTES_MOTION_NONE) {
      atomicMin(motion_check[MOTES_MOTION_FASTEST], group_index);
    }
  }
}
