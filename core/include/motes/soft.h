// Soft bodies by shape matching (Mueller, Heidelberger, Teschner, Gross 2005): splitting a body's
// particles into overlapping clusters and computing each cluster's rest data once, on the host
// (docs/architecture.md, "Soft bodies"). The device fits and pulls (shared/shape_matching.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "motes/api.h"
#include "motes/scene.h"
#include "motes/status.h"
#include "shared/shape_matching.h"

MOTES_API_BEGIN
namespace motes {

/// Clusters of soft bodies as the device holds them, and for each particle its members.
struct SoftClusters {
  std::vector<shared::Cluster> clusters;
  std::vector<shared::ClusterMember> members;  ///< cluster by cluster
  /// Per particle (in the order they were added), the indices of its members in `members`.
  std::vector<std::vector<std::uint32_t>> of_particle;
};

/// Adds one soft body's clusters: its particles are at `points` (world, at rest), device ids
/// first_particle + k, each of mass particle_mass. Clusters per spec.clusters (a grid over the
/// points' bounding box, each cell grown by half a cell on every side; empty cells dropped);
/// members weigh particle_mass / (clusters holding the particle); rest terms about each cluster's
/// mass-weighted mean (quadratic terms too); A_qq inverted in double (a pseudo-inverse where the
/// points are flat or on a line); spec.damping (1/s) as the fraction 1 - exp(-damping substep) per
/// substep. Fails on a stiffness outside (0, 1], beta outside [0, 1], a negative damping or a
/// cluster count below 1.
Status add_soft_body(const SoftSpec& spec, const std::vector<Eigen::Vector3d>& points,
                     double particle_mass, double substep, std::uint32_t first_particle,
                     SoftClusters& out);

/// ClusterGather for soft particles [first, first + count): the offsets then the member ids.
std::vector<std::uint32_t> cluster_gather(const SoftClusters& soft);

}  // namespace motes
MOTES_API_END
