// clusters_goal: one thread per soft-body particle damps it toward its clusters' rigid motion
// (cluster_damp) and moves it toward their goals (the sum of
// shared/shape_matching.h: cluster_shift over its members in ClusterGather order), its velocity by
// the same displacement / dt, and asks for a neighbour-list rebuild when it has moved too far
// since the last build (one store per block at most).
#include "cuda_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "shared/shape_matching.h"

namespace motes::cuda {

using shared::uint;
using shared::vec3;
using shared::vec4;

namespace {

__global__ void clusters_goal_kernel(shared::StepParams p,
                                     const shared::ClusterMember* __restrict__ members,
                                     const shared::ClusterFrame* __restrict__ frames,
                                     const uint* __restrict__ gather, vec4* __restrict__ pos,
                                     vec4* __restrict__ vel, const vec4* __restrict__ ref,
                                     uint* __restrict__ state) {
  const std::uint64_t k = std::uint64_t{blockIdx.x} * blockDim.x + threadIdx.x;
  const std::uint64_t i = p.soft_first + k;
  bool moved = false;
  if (i < p.linked_first) {
    vec4 x = pos[i];
    vec4 v = vel[i];
    vec3 shift(0.0f);
    vec3 damp(0.0f);
    for (uint j = gather[k]; j < gather[k + 1]; ++j) {
      const shared::ClusterMember m = members[gather[j]];
      shift += shared::cluster_shift(frames[m.cluster], m, shared::xyz(x), v.w);
      damp += shared::cluster_damp(frames[m.cluster], m, shared::xyz(x), shared::xyz(v), v.w);
    }
    v = vec4(shared::xyz(v) + damp, v.w);
    shared::constraint_apply(x, v, shift, 1.0f / p.gravity_dt.w);
    pos[i] = x;
    vel[i] = v;
    moved = shared::neighbour_moved_too_far(x, ref[i], p.neighbour_skin);
  }
  if (__syncthreads_or(moved) != 0 && threadIdx.x == 0) state[MOTES_NEIGHBOUR_REBUILD] = 1;
}

}  // namespace

void CudaDevice::launch_clusters_goal(const shared::StepParams& p) {
  const std::uint32_t count = p.linked_first - p.soft_first;
  if (count == 0 || p.cluster_count == 0) return;
  clusters_goal_kernel<<<blocks_for(count), kBlock, 0, stream_>>>(
      p, buf<shared::ClusterMember>(Buffer::ClusterMembers),
      buf<shared::ClusterFrame>(Buffer::ClusterFrames), buf<uint>(Buffer::ClusterGather),
      buf<vec4>(Buffer::ParticlePos), buf<vec4>(Buffer::ParticleVel),
      buf<vec4>(Buffer::NeighbourRefPos), buf<uint>(Buffer::NeighbourState));
}

}  // namespace motes::cuda
