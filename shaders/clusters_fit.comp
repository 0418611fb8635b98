#version 450
// clusters_fit: one thread per shape-matching cluster sums the centre of mass and moments of its
// members in member order, then writes the cluster's frame and, in a third pass, the drift and moment of its pulls and
// damping (shared/shape_matching.h); as
// backends/openmp/clusters_fit.cpp.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

void main() {
  uint k = thread_index();
  if (k >= p.cluster_count) return;
  Cluster cl = clusters[k];
  vec4 sum = vec4(0.0f);
  vec3 momentum = vec3(0.0f);
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    ClusterMember m = cluster_members[j];
    sum = cluster_centre_add(sum, particle_pos[m.particle], m.mass);
    momentum = cluster_momentum_add(momentum, particle_vel[m.particle], m.mass);
  }
  vec3 centre = xyz(sum) / sum.w;
  vec3 mean_v = momentum / sum.w;
  ClusterSums sums = cluster_sums_zero();
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    ClusterMember m = cluster_members[j];
    cluster_sums_add(sums, xyz(particle_pos[m.particle]) - centre, xyz(particle_vel[m.particle]), mean_v, m,
                     cl.mode);
  }
  ClusterFrame f = cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, cluster_frames[k].rotation);
  ClusterPulls pulls = cluster_pulls_zero();
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    ClusterMember m = cluster_members[j];
    cluster_pulls_add(pulls, f, m, xyz(particle_pos[m.particle]), xyz(particle_vel[m.particle]));
  }
  f = cluster_frame_finish(f, sums, pulls);
  cluster_frames[k] = f;
}
