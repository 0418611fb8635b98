// clusters_fit and clusters_goal (soft bodies, shared/shape_matching.h) against the oracle.
//
// Layouts: soft boxes made by motes::add_soft_body (rigid, linear and quadratic goals, overlapping
// clusters, damping), deformed by random offsets of up to 2 mm and moving with random velocities,
// between free spheres before them and cloth particles after them (so that the soft range
// [soft_first, linked_first) is tested); a line and a single particle (degenerate fits); and 1200
// small bodies (more workgroups than one dispatch dimension holds under the 2D test).
//
// clusters_fit: every other buffer poisoned; the frames' rotation, centre and mass, goal columns,
// mean velocity and angular velocity by NMSE 1e-10 (the fit's float sums in member order on
// every backend; a GPU's fused multiply-adds move the rotation extraction by about 1e-7 rad). The
// drift and spin words are rounding-sized corrections of each backend's own sums and are checked
// through clusters_goal, not against the oracle's.
//
// clusters_goal: the oracle's frames written as input; positions xyz by NMSE 1e-10, velocities
// by their largest difference in units of ulp(largest coordinate) / dt (a displacement that
// rounds the other way on another backend changes a velocity by ulp / dt, as for
// constraints_solve): at most 16; w bitwise; particles outside [soft_first, linked_first) bitwise
// as written; the rebuild word of NeighbourState set exactly when a particle ends 0.45 skin or
// more from its NeighbourRefPos.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "motes/soft.h"
#include "reference/reference.h"
#include "shared/neighbours.h"
#include "shared/shape_matching.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;
using motes_ref::Cluster;
using motes_ref::ClusterFrame;
using motes_ref::ClusterMember;

constexpr double kClustersTolerance = 1.0e-10;
constexpr double kClustersVelocityUlps = 16.0;
constexpr float kClustersSkin = 0.004f;
constexpr float kDt = 1.0e-4f;

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

SoftCase make_case(std::uint32_t seed, const std::vector<BodyPlan>& bodies, std::size_t before,
                   std::size_t after) {
  Rng rng(seed);
  SoftCase c;
  motes_ref::Particles& p = c.particles;
  const auto add_free = [&](std::size_t n, std::uint32_t body) {
    for (std::size_t k = 0; k < n; ++k) {
      p.pos.emplace_back(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                         rng.uniform(-1.0f, 1.0f), 0.005f);
      p.vel.emplace_back(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                         rng.uniform(-1.0f, 1.0f), 1000.0f);
      p.body.push_back(body + static_cast<std::uint32_t>(k));
      p.material.push_back(0);
    }
  };
  add_free(before, 0u);
  c.params.soft_first = static_cast<uint>(p.size());
  std::uint32_t body_word = static_cast<std::uint32_t>(before);
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const BodyPlan& plan = bodies[b];
    motes::SoftSpec spec;
    spec.stiffness = static_cast<double>(rng.uniform(0.05f, 1.0f));
    spec.mode = plan.mode;
    spec.beta =
        plan.mode == motes::SoftMode::Rigid ? 0.0 : static_cast<double>(rng.uniform(0.2f, 0.8f));
    spec.damping = static_cast<double>(rng.uniform(0.0f, 200.0f));
    spec.clusters = plan.clusters;
    const Eigen::Vector3d origin(rng.uniform(-2.0f, 2.0f), rng.uniform(0.0f, 2.0f),
                                 rng.uniform(-2.0f, 2.0f));
    const Eigen::Vector3d velocity(rng.uniform(-2.0f, 2.0f), rng.uniform(-2.0f, 2.0f),
                                   rng.uniform(-2.0f, 2.0f));
    std::vector<Eigen::Vector3d> rest;
    for (int z = 0; z < plan.cells.z(); ++z) {
      for (int y = 0; y < plan.cells.y(); ++y) {
        for (int x = 0; x < plan.cells.x(); ++x) {
          rest.push_back(origin + 0.01 * Eigen::Vector3d(x, y, z));
        }
      }
    }
    const auto first = static_cast<std::uint32_t>(p.size());
    const motes::Status s = motes::add_soft_body(spec, rest, 1.0e-3, kDt, first, c.soft);
    EXPECT_TRUE(s) << s.message();
    for (const Eigen::Vector3d& x : rest) {
      p.pos.emplace_back(static_cast<float>(x.x()) + rng.uniform(-0.002f, 0.002f),
                         static_cast<float>(x.y()) + rng.uniform(-0.002f, 0.002f),
                         static_cast<float>(x.z()) + rng.uniform(-0.002f, 0.002f), 0.005f);
      p.vel.emplace_back(static_cast<float>(velocity.x()) + rng.uniform(-0.3f, 0.3f),
                         static_cast<float>(velocity.y()) + rng.uniform(-0.3f, 0.3f),
                         static_cast<float>(velocity.z()) + rng.uniform(-0.3f, 0.3f), 1000.0f);
      p.body.push_back(body_word);
      p.material.push_back(0);
    }
    ++body_word;
  }
  c.params.linked_first = static_cast<uint>(p.size());
  add_free(after, motes::shared::linked_body(0u, 0u, 0u));
  p.rigid = 0;
  // Last rotations near the identity, as after a step of a slowly turning body.
  for (std::size_t k = 0; k < c.soft.clusters.size(); ++k) {
    const float a = rng.uniform(-0.05f, 0.05f);
    ClusterFrame f{};
    f.rotation = motes::shared::quat_normalize(vec4(a, -0.5f * a, 0.3f * a, 1.0f));
    c.frames.push_back(f);
  }
  c.params.gravity_dt = vec4(0.0f, -9.81f, 0.0f, kDt);
  c.params.particle_count = static_cast<uint>(p.size());
  c.params.neighbour_skin = kClustersSkin;
  c.params.cluster_count = static_cast<uint>(c.soft.clusters.size());
  c.params.material_count = 1;
  c.params.neighbour_capacity = 16;
  c.sizes.particles = static_cast<std::uint32_t>(p.size());
  c.sizes.table = motes::grid_table_size(c.sizes.particles);
  c.params.table_mask = c.sizes.table - 1;
  c.sizes.materials = 1;
  c.sizes.neighbour_capacity = 16;
  c.sizes.soft_particles = c.params.linked_first - c.params.soft_first;
  c.sizes.clusters = static_cast<std::uint32_t>(c.soft.clusters.size());
  c.sizes.cluster_members = static_cast<std::uint32_t>(c.soft.members.size());
  return c;
}

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

class Clusters : public DeviceTest {
 protected:
  void write_inputs(const SoftCase& c, const std::vector<ClusterFrame>& frames) {
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, c.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, c.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Clusters, c.soft.clusters));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ClusterMembers, c.soft.members));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ClusterFrames, frames));
  }

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
    const double ulp_per_dt = coordinate_ulp(want.pos) / static_cast<double>(kDt);
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

std::vector<BodyPlan> three_modes() {
  return {{{7, 7, 8}, motes::SoftMode::Rigid, {1, 1, 1}},
          {{6, 4, 5}, motes::SoftMode::Linear, {2, 1, 1}},
          {{5, 5, 5}, motes::SoftMode::Quadratic, {2, 2, 2}}};
}

std::vector<BodyPlan> degenerate() {
  return {{{9, 1, 1}, motes::SoftMode::Linear, {1, 1, 1}},
          {{1, 1, 1}, motes::SoftMode::Quadratic, {1, 1, 1}},
          {{5, 5, 1}, motes::SoftMode::Quadratic, {1, 1, 1}}};
}

std::vector<BodyPlan> many() {
  return std::vector<BodyPlan>(1200, {{2, 2, 2}, motes::SoftMode::Linear, {1, 1, 1}});
}

TEST_P(Clusters, FitThreeModes) { run_fit("three modes", make_case(301, three_modes(), 17, 9)); }
TEST_P(Clusters, FitDegenerate) {
  run_fit("line, point, plane", make_case(302, degenerate(), 0, 0));
}
TEST_P(Clusters, FitMany) { run_fit("1200 bodies", make_case(303, many(), 5, 0)); }
TEST_P(Clusters, GoalThreeModes) {
  run_goal("three modes", make_case(304, three_modes(), 17, 9), false);
}
TEST_P(Clusters, GoalThreeModesMoved) {
  run_goal("three modes moved_far", make_case(305, three_modes(), 17, 9), true);
}
TEST_P(Clusters, GoalDegenerate) {
  run_goal("line, point, plane", make_case(306, degenerate(), 3, 3), false);
}
TEST_P(Clusters, GoalMany) { run_goal("1200 bodies", make_case(307, many(), 0, 5), true); }

INSTANTIATE_TEST_SUITE_P(Conformance, Clusters, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
