// clusters_fit: per shape-matching cluster, the centre of mass and moments of its members summed in
// member order, then the cluster's frame (shared/shape_matching.h: cluster_frame) and, in a third
// pass, the drift and moment of its pulls and damping (cluster_pulls_add).
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/shape_matching.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::clusters_fit(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto count = static_cast<std::int64_t>(p.cluster_count);
  const auto* clusters = buf<shared::Cluster>(Buffer::Clusters);
  const auto* members = buf<shared::ClusterMember>(Buffer::ClusterMembers);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  auto* frames = buf<shared::ClusterFrame>(Buffer::ClusterFrames);

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(count * 64))
  for (std::int64_t k = 0; k < count; ++k) {
    const shared::Cluster& cl = clusters[k];
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
      const shared::ClusterMember& m = members[j];
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
  record(Kernel::ClustersFit, start);
}

}  // namespace motes::openmp
