// clusters_fit: one warp per shape-matching cluster. Each of its 32 lanes sums every 32nd member
// (lane, lane + 32, ...) in member order, the lanes' sums are combined by a fixed butterfly
// (__shfl_xor_sync: every lane ends with the same, bitwise, whatever the timing), then every lane
// computes the cluster's frame (shared/shape_matching.h), and the same for the third pass (the
// drift and moment of its pulls and damping); lane 0 writes the frame. The contract's order is
// openmp's sequential sum: this order rounds differently, within the conformance tolerances. A
// thread per cluster walked 392 members three times in sequence: 1.76 ms for 10,000 cubes on an
// H100, latency-bound (docs/benchmarks.md, W4).
#include "cuda_device.h"
#include "shared/shape_matching.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

constexpr unsigned kWarp = 32;
constexpr unsigned kFullMask = 0xffffffffu;

__device__ float warp_sum(float x) {
  for (unsigned offset = kWarp / 2; offset > 0; offset /= 2) {
    x += __shfl_xor_sync(kFullMask, x, static_cast<int>(offset));
  }
  return x;
}

__device__ vec3 warp_sum(vec3 v) { return vec3(warp_sum(v.x), warp_sum(v.y), warp_sum(v.z)); }

__device__ vec4 warp_sum(vec4 v) {
  return vec4(warp_sum(v.x), warp_sum(v.y), warp_sum(v.z), warp_sum(v.w));
}

__global__ void clusters_fit_kernel(shared::StepParams p,
                                    const shared::Cluster* __restrict__ clusters,
                                    const shared::ClusterMember* __restrict__ members,
                                    const vec4* __restrict__ pos, const vec4* __restrict__ vel,
                                    shared::ClusterFrame* __restrict__ frames) {
  const std::uint64_t thread = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  const std::uint64_t k = thread / kWarp;
  const unsigned lane = threadIdx.x % kWarp;
  // A whole warp has one cluster (blocks are multiples of 32 threads): whole warps leave together.
  if (k >= p.cluster_count) return;
  const shared::Cluster cl = clusters[k];
  const uint end = cl.first + cl.count;
  vec4 sum(0.0f);
  vec3 momentum(0.0f);
  for (uint j = cl.first + lane; j < end; j += kWarp) {
    sum = shared::cluster_centre_add(sum, pos[members[j].particle], members[j].mass);
    momentum = shared::cluster_momentum_add(momentum, vel[members[j].particle], members[j].mass);
  }
  sum = warp_sum(sum);
  momentum = warp_sum(momentum);
  const vec3 centre = shared::xyz(sum) / sum.w;
  const vec3 mean_v = momentum / sum.w;
  shared::ClusterSums sums = shared::cluster_sums_zero();
  for (uint j = cl.first + lane; j < end; j += kWarp) {
    const shared::ClusterMember m = members[j];
    shared::cluster_sums_add(sums, shared::xyz(pos[m.particle]) - centre,
                             shared::xyz(vel[m.particle]), mean_v, m, cl.mode);
  }
  const int terms = cl.mode == MOTES_CLUSTER_QUADRATIC ? MOTES_CLUSTER_TERMS : 3;
  for (int t = 0; t < terms; ++t) sums.apq[t] = warp_sum(sums.apq[t]);
  sums.app_diagonal = warp_sum(sums.app_diagonal);
  sums.app_off = warp_sum(sums.app_off);
  sums.spin = warp_sum(sums.spin);
  shared::ClusterFrame f =
      shared::cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, frames[k].rotation);
  shared::ClusterPulls pulls = shared::cluster_pulls_zero();
  for (uint j = cl.first + lane; j < end; j += kWarp) {
    const shared::ClusterMember m = members[j];
    shared::cluster_pulls_add(pulls, f, m, shared::xyz(pos[m.particle]),
                              shared::xyz(vel[m.particle]));
  }
  pulls.drift = warp_sum(pulls.drift);
  pulls.moment = warp_sum(pulls.moment);
  pulls.damp_drift = warp_sum(pulls.damp_drift);
  pulls.damp_moment = warp_sum(pulls.damp_moment);
  f = shared::cluster_frame_finish(f, sums, pulls);
  if (lane == 0) frames[k] = f;
}

}  // namespace

void CudaDevice::launch_clusters_fit(const shared::StepParams& p) {
  if (p.cluster_count == 0) return;
  static_assert(kBlock % kWarp == 0, "whole warps per block");
  clusters_fit_kernel<<<blocks_for(std::uint64_t{p.cluster_count} * kWarp), kBlock, 0, stream_>>>(
      p, buf<shared::Cluster>(Buffer::Clusters), buf<shared::ClusterMember>(Buffer::ClusterMembers),
      buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<shared::ClusterFrame>(Buffer::ClusterFrames));
}

}  // namespace motes::cuda
