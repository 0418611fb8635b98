// What the soft-body cases share (test_clusters_fit.cpp, test_clusters_goal.cpp): soft boxes made
// by motes::add_soft_body between free spheres and cloth particles, their launch data, and the
// fixture that writes them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "conformance.h"
#include "motes/soft.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {

using motes_ref::ClusterFrame;

/// Bound on the NMSE of the frames (clusters_fit) and the positions (clusters_goal).
inline constexpr double kClustersTolerance = 1.0e-10;
/// Bound on clusters_goal's velocity differences, in ulp(largest coordinate) / dt.
inline constexpr double kClustersVelocityUlps = 16.0;
inline constexpr float kClustersSkin = 0.004f;
inline constexpr float kClustersDt = 1.0e-4f;

/// Particles (free spheres, then soft bodies, then cloth particles), clusters and launch data.
struct SoftCase {
  motes_ref::Particles particles;
  motes::SoftClusters soft;
  std::vector<ClusterFrame> frames;  // input: the last fit's rotations
  StepParams params{};
  motes::Sizes sizes;
};

struct BodyPlan {
  Eigen::Vector3i cells;
  motes::SoftMode mode;
  std::array<int, 3> clusters;
};

/// Free spheres (`before`), the soft `bodies` deformed by up to 2 mm and moving, then cloth
/// particles (`after`); the last rotations near the identity.
SoftCase make_soft_case(std::uint32_t seed, const std::vector<BodyPlan>& bodies, std::size_t before,
                        std::size_t after);

/// Rigid, linear and quadratic goals, overlapping clusters.
std::vector<BodyPlan> soft_three_modes();
/// A line, a single particle and a plane: degenerate fits.
std::vector<BodyPlan> soft_degenerate();
/// 1200 small bodies: more workgroups than one dispatch dimension holds under the 2D test.
std::vector<BodyPlan> soft_many();

/// The fixture of the soft-body cases.
class ClusterTest : public DeviceTest {
 protected:
  /// Writes the particles, the clusters and `frames`.
  void write_inputs(const SoftCase& c, const std::vector<ClusterFrame>& frames) {
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ParticlePos, c.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ParticleVel, c.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::Clusters, c.soft.clusters));
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ClusterMembers, c.soft.members));
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ClusterFrames, frames));
  }
};

}  // namespace motes_conf
