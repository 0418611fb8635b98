#version 450
// clusters_goal: one thread per soft-body particle damps it toward its clusters' rigid motion
// (cluster_damp) and moves it toward their goals (the sum of
// shared/shape_matching.h: cluster_shift over its members in ClusterGather order), its velocity by
// the same displacement / dt, and asks for a neighbour-list rebuild when it has moved too far
// since the last build (one store per workgroup at most); as backends/openmp/clusters_goal.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/neighbours.h"

shared uint group_moved;

void main() {
  uint k = thread_index();
  uint i = p.soft_first + k;
  if (gl_LocalInvocationID.x == 0u) group_moved = 0u;
  barrier();
  if (i < p.linked_first) {
    vec4 x = particle_pos[i];
    vec4 v = particle_vel[i];
    vec3 shift = vec3(0.0f);
    vec3 damp = vec3(0.0f);
    for (uint j = cluster_gather[k]; j < cluster_gather[k + 1u]; ++j) {
      ClusterMember m = cluster_members[cluster_gather[j]];
      shift += cluster_shift(cluster_frames[m.cluster], m, xyz(x), v.w);
      damp += cluster_damp(cluster_frames[m.cluster], m, xyz(x), xyz(v), v.w);
    }
    v = vec4(xyz(v) + damp, v.w);
    constraint_apply(x, v, shift, 1.0f / p.gravity_dt.w);
    particle_pos[i] = x;
    particle_vel[i] = v;
    if (neighbour_moved_too_far(x, neighbour_ref_pos[i], p.neighbour_skin)) {
      atomicOr(group_moved, 1u);
    }
  }
  barrier();
  if (gl_LocalInvocationID.x == 0u && group_moved != 0u) {
    neighbour_state[MOTES_NEIGHBOUR_REBUILD] = 1u;
  }
}
