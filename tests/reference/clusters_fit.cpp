// The oracle of clusters_fit (reference.h has the contract): each cluster's sums over its
// members in member order, in float, then the shared frame functions.
#include <cstddef>

#include "reference.h"

namespace motes_ref {

using motes::shared::vec3;
using motes::shared::xyz;

void clusters_fit(const std::vector<vec4>& pos, const std::vector<vec4>& vel,
                  const std::vector<Cluster>& clusters, const std::vector<ClusterMember>& members,
                  std::vector<ClusterFrame>& frames) {
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    const Cluster& cl = clusters[k];
    vec4 sum(0.0f);
    vec3 momentum(0.0f);
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      sum = motes::shared::cluster_centre_add(sum, pos[members[j].particle], members[j].mass);
      momentum =
          motes::shared::cluster_momentum_add(momentum, vel[members[j].particle], members[j].mass);
    }
    const vec3 centre = motes::shared::xyz(sum) / sum.w;
    const vec3 mean_v = momentum / sum.w;
    motes::shared::ClusterSums sums = motes::shared::cluster_sums_zero();
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      motes::shared::cluster_sums_add(sums, motes::shared::xyz(pos[members[j].particle]) - centre,
                                      motes::shared::xyz(vel[members[j].particle]), mean_v,
                                      members[j], cl.mode);
    }
    ClusterFrame f =
        motes::shared::cluster_frame(cl, sums, vec4(centre, sum.w), mean_v, frames[k].rotation);
    motes::shared::ClusterPulls pulls = motes::shared::cluster_pulls_zero();
    for (uint j = cl.first; j < cl.first + cl.count; ++j) {
      motes::shared::cluster_pulls_add(pulls, f, members[j], xyz(pos[members[j].particle]),
                                       xyz(vel[members[j].particle]));
    }
    frames[k] = motes::shared::cluster_frame_finish(f, sums, pulls);
  }
}

}  // namespace motes_ref
