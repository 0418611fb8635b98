#version 450
// clusters_fit: 32 threads per shape-matching cluster (8 clusters per workgroup). Each thread sums
// every 32nd member (lane, lane + 32, ...) in member order, the 32 sums are combined by a fixed
// tree in shared memory (group_sum: the same on every run), then every thread computes the
// cluster's frame (shared/shape_matching.h), and the same for the third pass (the drift and moment
// of its pulls and damping); lane 0 writes the frame. As backends/cuda/clusters_fit.cu (a warp per
// cluster); the contract's order is openmp's sequential sum, this one rounds within the
// conformance tolerances. Every thread reaches every barrier: threads of clusters beyond the count
// sum nothing and write nothing.
#extension GL_GOOGLE_include_directive : require
#define MOTES_STATE_READONLY  // writes no particle position, velocity, grid or list
#include "kernel_common.glsl"

#define LANES 32u

shared float partial[WORKGROUP_SIZE];

/// The sum over the 32 threads of this thread's cluster, in a fixed tree; every thread gets it.
float group_sum(float x) {
  uint t = gl_LocalInvocationID.x;
  partial[t] = x;
  barrier();
  for (uint offset = LANES / 2u; offset > 0u; offset /= 2u) {
    if ((t % LANES) < offset) partial[t] += partial[t + offset];
    barrier();
  }
  float total = partial[t - t % LANES];
  barrier();
  return total;
}

vec3 group_sum3(vec3 v) { return vec3(group_sum(v.x), group_sum(v.y), group_sum(v.z)); }

void main() {
  uint k = flat_group() * (WORKGROUP_SIZE / LANES) + gl_LocalInvocationID.x / LANES;
  uint lane = gl_LocalInvocationID.x % LANES;
  bool valid = k < p.cluster_count;
  Cluster cl;
  uint first = 0u;
  uint end = 0u;
  if (valid) {
    cl = clusters[k];
    first = cl.first;
    end = cl.first + cl.count;
  }
  vec4 sum = vec4(0.0f);
  vec3 momentum = vec3(0.0f);
  for (uint j = first + lane; j < end; j += LANES) {
    ClusterMember m = cluster_members[j];
    sum = cluster_centre_add(sum, particle_pos[m.particle], m.mass);
    momentum = cluster_momentum_add(momentum, particle_vel[m.particle], m.mass);
  }
  sum = vec4(group_sum3(xyz(sum)), group_sum(sum.w));
  momentum = group_sum3(momentum);
  vec3 centre = xyz(sum) / sum.w;
  vec3 mean_v = momentum / sum.w;
  ClusterSums sums = cluster_sums_zero();
  for (uint j = first + lane; j < end; j += LANES) {
    ClusterMember m = cluster_members[j];
    cluster_sums_add(sums, xyz(particle_pos[m.particle]) - centre, xyz(particle_vel[m.particle]),
                     mean_v, m, cl.mode);
  }
  // Every column, whatever the mode (a barrier needs the same trip count in every thread).
  for (int t = 0; t < MOTES_CLUSTER_TERMS; ++t) sums.apq[t] = group_sum3(sums.apq[t]);
  sums.app_diagonal = group_sum3(sums.app_diagonal);
  sums.app_off = group_sum3(sums.app_off);
  sums.spin = group_sum3(sums.spin);
  ClusterFrame f;
  if (valid) {
    f = cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, cluster_frames[k].rotation);
  }
  ClusterPulls pulls = cluster_pulls_zero();
  for (uint j = first + lane; j < end; j += LANES) {
    ClusterMember m = cluster_members[j];
    cluster_pulls_add(pulls, f, m, xyz(particle_pos[m.particle]), xyz(particle_vel[m.particle]));
  }
  pulls.drift = group_sum3(pulls.drift);
  pulls.moment = group_sum3(pulls.moment);
  pulls.damp_drift = group_sum3(pulls.damp_drift);
  pulls.damp_moment = group_sum3(pulls.damp_moment);
  if (valid && lane == 0u) cluster_frames[k] = cluster_frame_finish(f, sums, pulls);
}
