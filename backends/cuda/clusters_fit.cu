// clusters_fit: one thread per shape-matching cluster sums the centre of mass and moments of its
// members in member order, then writes the cluster's frame and, in a third pass, the drift of its
// goals (shared/shape_matching.h).
#include "cuda_device.h"
#include "shared/shape_matching.h"

namespace motes::cuda {

using shared::uint;
using shared::vec4;

namespace {

__global__ void clusters_fit_kernel(shared::StepParams p,
                                    const shared::Cluster* __restrict__ clusters,
                                    const shared::ClusterMember* __restrict__ members,
                                    const vec4* __restrict__ pos, const vec4* __restrict__ vel,
                                    shared::ClusterFrame* __restrict__ frames) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (k >= p.cluster_count) return;
  const shared::Cluster cl = clusters[k];
  vec4 sum(0.0f);
  shared::vec3 momentum(0.0f);
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    sum = shared::cluster_centre_add(sum, pos[members[j].particle], members[j].mass);
    momentum = shared::cluster_momentum_add(momentum, vel[members[j].particle], members[j].mass);
  }
  const shared::vec3 centre = shared::xyz(sum) / sum.w;
  const shared::vec3 mean_v = momentum / sum.w;
  shared::ClusterSums sums = shared::cluster_sums_zero();
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    const shared::ClusterMember m = members[j];
    shared::cluster_sums_add(sums, shared::xyz(pos[m.particle]) - centre,
                             shared::xyz(vel[m.particle]), mean_v, m, cl.mode);
  }
  shared::ClusterFrame f =
      shared::cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, frames[k].rotation);
  shared::ClusterPulls pulls = shared::cluster_pulls_zero();
  for (uint j = cl.first; j < cl.first + cl.count; ++j) {
    const shared::ClusterMember& m = members[j];
    shared::cluster_pulls_add(pulls, f, m, shared::xyz(pos[m.particle]),
                              shared::xyz(vel[m.particle]));
  }
  f = shared::cluster_frame_finish(f, sums, pulls);
  frames[k] = f;
}

}  // namespace

void CudaDevice::launch_clusters_fit(const shared::StepParams& p) {
  if (p.cluster_count == 0) return;
  clusters_fit_kernel<<<blocks_for(p.cluster_count), kBlock, 0, stream_>>>(
      p, buf<shared::Cluster>(Buffer::Clusters), buf<shared::ClusterMember>(Buffer::ClusterMembers),
      buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<shared::ClusterFrame>(Buffer::ClusterFrames));
}

}  // namespace motes::cuda
