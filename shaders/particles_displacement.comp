#version 450
// particles_displacement: the largest squared distance a particle has moved since the ranks last
// partitioned the scene (shared/halo.h: displacement2_bits), pass args.x: a reset (one thread),
// then the reduction (a workgroup max in shared memory, then one atomicMax per workgroup). An
// integer max of float bits: the result does not depend on the order the workgroups run in.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY
#include "kernel_common.glsl"
#include "shared/halo.h"

shared uint group_largest;

void main() {
  if (args.x == MOTES_PARTITION_PASS_RESET) {
    if (thread_index() == 0u) partition_check[MOTES_PARTITION_DISPLACEMENT2] = 0u;
    return;
  }
  if (gl_LocalInvocationID.x == 0u) group_largest = 0u;
  barrier();
  uint i = thread_index();
  if (i < p.particle_count) {
    atomicMax(group_largest, displacement2_bits(particle_pos[i], partition_ref_pos[i]));
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_largest != 0u) {
    atomicMax(partition_check[MOTES_PARTITION_DISPLACEMENT2], group_largest);
  }
}
