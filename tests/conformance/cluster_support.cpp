// What the soft-body cases share (cluster_support.h).
#include "cluster_support.h"

#include <Eigen/Core>

#include "shared/links.h"
#include "shared/shape_matching.h"

namespace motes_conf {

SoftCase make_soft_case(std::uint32_t seed, const std::vector<BodyPlan>& bodies, std::size_t before,
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
    const motes::Status s = motes::add_soft_body(spec, rest, 1.0e-3, kClustersDt, first, c.soft);
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
  c.params.gravity_dt = vec4(0.0f, -9.81f, 0.0f, kClustersDt);
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

std::vector<BodyPlan> soft_three_modes() {
  return {{{7, 7, 8}, motes::SoftMode::Rigid, {1, 1, 1}},
          {{6, 4, 5}, motes::SoftMode::Linear, {2, 1, 1}},
          {{5, 5, 5}, motes::SoftMode::Quadratic, {2, 2, 2}}};
}

std::vector<BodyPlan> soft_degenerate() {
  return {{{9, 1, 1}, motes::SoftMode::Linear, {1, 1, 1}},
          {{1, 1, 1}, motes::SoftMode::Quadratic, {1, 1, 1}},
          {{5, 5, 1}, motes::SoftMode::Quadratic, {1, 1, 1}}};
}

std::vector<BodyPlan> soft_many() {
  return std::vector<BodyPlan>(1200, {{2, 2, 2}, motes::SoftMode::Linear, {1, 1, 1}});
}

}  // namespace motes_conf
