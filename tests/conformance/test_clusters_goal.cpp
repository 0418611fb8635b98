// clusters_goal (soft bodies, shared/shape_matching.h) against the oracle.
//
// Layouts (cluster_support.h): soft boxes made by motes::add_soft_body (rigid, linear and
// quadratic goals, overlapping clusters, damping), deformed by random offsets of up to 2 mm and
// moving with random velocities, between free spheres before them and cloth particles after them
// (so that the soft range [soft_first, linked_first) is tested); a line and a single particle
// (degenerate fits); and 1200 small bodies (more workgroups than one dispatch dimension holds
// under the 2D test).
//
// The oracle's frames written as input; positions xyz by NMSE 1e-10, velocities by their largest
// difference in units of ulp(largest coordinate) / dt (a displacement that rounds the other way
// on another backend changes a velocity by ulp / dt, as for constraints_solve): at most 16; w
// bitwise; particles outside [soft_first, linked_first) bitwise as written; the rebuild word of
// NeighbourState set exactly when a particle ends 0.45 skin or more from its NeighbourRefPos.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cluster_support.h"
#include "conformance.h"
#include "reference/reference.h"
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

class ClustersGoal : public ClusterTest {
 protected:
  void run_goal(const std::string& layout, const SoftCase& c, bool far) {
    std::vector<ClusterFrame> frames = c.frames;
    motes_ref::clusters_fit(c.particles.pos, c.particles.vel, c.soft.clusters, c.soft.members,
                            frames);
    motes_ref::Particles want = c.particles;
    motes_ref::clusters_goal(want, c.soft.members, frames, c.params);
    Rng rng(c.sizes.particles + 7u);
    std::vector<vec4> ref = moved_by(rng, want.pos, kClustersSkin, 0.3f);
    std::size_t moved_particle = c.particles.size();
    if (far && c.params.linked_first > c.params.soft_first) {
      moved_particle = (c.params.soft_first + c.params.linked_first) / 2;
      ref[moved_particle] = moved_by(rng, {want.pos[moved_particle]}, kClustersSkin, 0.6f)[0];
    }
    motes_ref::Particles again = c.particles;
    const bool rebuild = motes_ref::clusters_goal(again, c.soft.members, frames, c.params, ref);
    ASSERT_EQ(rebuild, moved_particle < c.particles.size()) << "the case's own premise";
    const std::vector<uint> state_in = {0u, 3u, 0u, 7u};
    const std::vector<uint> gather = motes::cluster_gather(c.soft);

    ASSERT_NO_FATAL_FAILURE(allocate(c.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::Clusters,
                        Buffer::ClusterMembers, Buffer::ClusterFrames, Buffer::ClusterGather,
                        Buffer::NeighbourRefPos, Buffer::NeighbourState}));
    ASSERT_NO_FATAL_FAILURE(write_inputs(c, frames));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ClusterGather, gather));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ClustersGoal, c.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));
    std::vector<uint> state_want = state_in;
    if (rebuild) state_want[MOTES_NEIGHBOUR_REBUILD] = 1u;
    const std::size_t a = c.params.soft_first;
    const std::size_t b = c.params.linked_first;
    const std::size_t n = c.particles.size();

    begin_case("clusters_goal/" + layout, b - a);
    check_close("ParticlePos", pos, want.pos, kClustersTolerance, Part::Xyz);
    const double ulp_per_dt = coordinate_ulp(want.pos) / static_cast<double>(kClustersDt);
    check_at_most("ParticleVel", "max dv (ulp/dt)", max_distance(vel, want.vel) / ulp_per_dt,
                  kClustersVelocityUlps);
    check_w_identical("ParticlePos.w (radius) kept", pos, c.particles.pos);
    check_w_identical("ParticleVel.w (inverse mass) kept", vel, c.particles.vel);
    check_identical("ParticlePos outside the soft range", slice(pos, 0, a),
                    slice(c.particles.pos, 0, a));
    check_identical("ParticlePos after the soft range", slice(pos, b, n),
                    slice(c.particles.pos, b, n));
    check_identical("ParticleVel outside the soft range", slice(vel, 0, a),
                    slice(c.particles.vel, 0, a));
    check_identical("ParticleVel after the soft range", slice(vel, b, n),
                    slice(c.particles.vel, b, n));
    check_identical("NeighbourState", state, state_want);
    end_case();
  }
};

TEST_P(ClustersGoal, ThreeModes) {
  run_goal("three modes", make_soft_case(304, soft_three_modes(), 17, 9), false);
}
TEST_P(ClustersGoal, ThreeModesMoved) {
  run_goal("three modes moved_far", make_soft_case(305, soft_three_modes(), 17, 9), true);
}
TEST_P(ClustersGoal, Degenerate) {
  run_goal("line, point, plane", make_soft_case(306, soft_degenerate(), 3, 3), false);
}
TEST_P(ClustersGoal, Many) {
  run_goal("1200 bodies", make_soft_case(307, soft_many(), 0, 5), true);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ClustersGoal, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
