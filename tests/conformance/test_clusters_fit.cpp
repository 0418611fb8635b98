// clusters_fit (soft bodies, shared/shape_matching.h) against the oracle.
//
// Layouts (cluster_support.h): soft boxes made by motes::add_soft_body (rigid, linear and
// quadratic goals, overlapping clusters, damping), deformed by random offsets of up to 2 mm and
// moving with random velocities, between free spheres before them and cloth particles after them
// (so that the soft range [soft_first, linked_first) is tested); a line and a single particle
// (degenerate fits); and 1200 small bodies (more workgroups than one dispatch dimension holds
// under the 2D test).
//
// Every other buffer poisoned; the frames' rotation, centre and mass, goal columns, mean velocity
// and angular velocity by NMSE 1e-10 (the fit's float sums in member order on every backend; a
// GPU's fused multiply-adds move the rotation extraction by about 1e-7 rad). The drift and spin
// words are rounding-sized corrections of each backend's own sums and are checked through
// clusters_goal (test_clusters_goal.cpp), not against the oracle's.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cluster_support.h"
#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

std::vector<vec4> frame_part(const std::vector<ClusterFrame>& frames, int part) {
  std::vector<vec4> out;
  for (const ClusterFrame& f : frames) {
    switch (part) {
      case 0:
        out.push_back(f.rotation);
        break;
      case 1:
        out.push_back(f.centre);
        break;
      case 2:
        for (const vec4& t : f.t) out.push_back(t);
        break;
      case 3:
        out.push_back(f.velocity);
        break;
      default:
        out.push_back(f.omega);
        break;
    }
  }
  return out;
}

class ClustersFit : public ClusterTest {
 protected:
  void run_fit(const std::string& layout, const SoftCase& c) {
    std::vector<ClusterFrame> want = c.frames;
    motes_ref::clusters_fit(c.particles.pos, c.particles.vel, c.soft.clusters, c.soft.members,
                            want);
    ASSERT_NO_FATAL_FAILURE(allocate(c.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::Clusters,
                        Buffer::ClusterMembers, Buffer::ClusterFrames}));
    ASSERT_NO_FATAL_FAILURE(write_inputs(c, c.frames));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ClustersFit, c.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<ClusterFrame> got;
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ClusterFrames, got));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));
    begin_case("clusters_fit/" + layout, c.soft.clusters.size());
    check_close("ClusterFrames.rotation", frame_part(got, 0), frame_part(want, 0),
                kClustersTolerance);
    check_close("ClusterFrames.centre (w: mass)", frame_part(got, 1), frame_part(want, 1),
                kClustersTolerance);
    check_close("ClusterFrames.t", frame_part(got, 2), frame_part(want, 2), kClustersTolerance);
    check_close("ClusterFrames.velocity (w: damping)", frame_part(got, 3), frame_part(want, 3),
                kClustersTolerance);
    check_close("ClusterFrames.omega", frame_part(got, 4), frame_part(want, 4), kClustersTolerance);
    check_identical("ParticlePos (read only)", pos, c.particles.pos);
    check_identical("ParticleVel (read only)", vel, c.particles.vel);
    end_case();
  }
};

TEST_P(ClustersFit, ThreeModes) {
  run_fit("three modes", make_soft_case(301, soft_three_modes(), 17, 9));
}
TEST_P(ClustersFit, Degenerate) {
  run_fit("line, point, plane", make_soft_case(302, soft_degenerate(), 0, 0));
}
TEST_P(ClustersFit, Many) { run_fit("1200 bodies", make_soft_case(303, soft_many(), 5, 0)); }

INSTANTIATE_TEST_SUITE_P(Conformance, ClustersFit, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
