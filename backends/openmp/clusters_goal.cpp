// clusters_goal: every soft-body particle damped toward its clusters' rigid motion (cluster_damp),
// then moved toward their goals (the sum of shared/shape_matching.h: cluster_shift over its
// members, in ClusterGather order), its velocity by the same displacement / dt, and a
// neighbour-list rebuild asked for when one has moved too far since the last build.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "shared/shape_matching.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::clusters_goal(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto first = static_cast<std::int64_t>(p.soft_first);
  const auto end = static_cast<std::int64_t>(p.linked_first);
  const float inv_dt = 1.0f / p.gravity_dt.w;
  const auto* members = buf<shared::ClusterMember>(Buffer::ClusterMembers);
  const auto* frames = buf<shared::ClusterFrame>(Buffer::ClusterFrames);
  const uint* gather = buf<uint>(Buffer::ClusterGather);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  uint moved = 0;

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(end - first)) \
    reduction(|                                                                         \
              : moved)
  for (std::int64_t i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i - first);
    const vec3 x = shared::xyz(pos[i]);
    const vec3 v = shared::xyz(vel[i]);
    vec3 shift(0.0f);
    vec3 damp(0.0f);
    for (uint j = gather[k]; j < gather[k + 1]; ++j) {
      const shared::ClusterMember& m = members[gather[j]];
      shift += shared::cluster_shift(frames[m.cluster], m, x, vel[i].w);
      damp += shared::cluster_damp(frames[m.cluster], m, x, v, vel[i].w);
    }
    vel[i] = vec4(v + damp, vel[i].w);
    shared::constraint_apply(pos[i], vel[i], shift, inv_dt);
    moved |= shared::neighbour_moved_too_far(pos[i], ref[i], p.neighbour_skin) ? 1u : 0u;
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  record(Kernel::ClustersGoal, start);
}

}  // namespace motes::openmp
