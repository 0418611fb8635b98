// The cases of constraints_solve and constraints_relax (test_constraints_solve.cpp says what
// they are and how they are checked): the coloured layouts, and the fixture that runs one either
// as a call per colour and sweep or as one call for every sweep.
#ifndef MOTES_CONFORMANCE_CONSTRAINTS_CASES_H
#define MOTES_CONFORMANCE_CONSTRAINTS_CASES_H

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "motes/cloth.h"
#include "reference/reference.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {

using motes::Buffer;
using motes::shared::Constraint;

constexpr double kConstraintsSolveTolerance = 1.0e-10;
constexpr double kConstraintsVelocityUlps = 16.0;
constexpr int kIterations = 2;
/// The skin of these cases: the rebuild word is set when a particle is 0.45 skin from its
/// reference at any projection of the last sweep. Projections move particles by up to a few mm in
/// between, so the references sit 0.3 skin from the final positions (no rebuild) and one 0.6 skin
/// (rebuild).
constexpr float kConstraintsSkin = 0.1f;

/// A world whose free particles are replaced by a linked object's points (each moved by up to
/// `jitter` so that every constraint has an error to remove) and its constraints, coloured.
struct LinkedCase {
  World world;
  motes::ConstraintColouring colouring;
};

inline LinkedCase from_linked(std::uint32_t seed, const motes::LinkedSpec& spec, float jitter) {
  Rng rng(seed);
  LinkedCase c;
  c.world = make_world(rng, std::vector<vec4>(spec.points.size(), vec4(0.0f, 0.0f, 0.0f, 0.004f)),
                       0u, false, kTestSkin);
  motes_ref::Particles& p = c.world.particles;
  // Every particle free: the object's points, lattice bodies, some pinned.
  p.rigid = 0;
  p.local.clear();
  c.world.bodies = motes_ref::Bodies{};
  c.world.bodies.first = {0u};
  c.world.sizes.rigid_particles = 0;
  c.world.sizes.bodies = 0;
  c.world.params.rigid_particle_count = 0;
  c.world.params.body_count = 0;
  std::vector<bool> pinned(spec.points.size(), false);
  for (const std::uint32_t k : spec.pinned) pinned[k] = true;
  for (std::size_t i = 0; i < spec.points.size(); ++i) {
    const Eigen::Vector3d& x = spec.points[i];
    p.pos[i] = vec4(static_cast<float>(x.x()) + rng.uniform(-jitter, jitter),
                    static_cast<float>(x.y()) + rng.uniform(-jitter, jitter),
                    static_cast<float>(x.z()) + rng.uniform(-jitter, jitter), 0.004f);
    p.vel[i] = vec4(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                    pinned[i] ? 0.0f : rng.uniform(500.0f, 2000.0f));
    p.body[i] = motes::shared::linked_body(0u, spec.lattice[i][0], spec.lattice[i][1]);
  }
  std::vector<Constraint> constraints;
  for (const motes::LinkSpec& l : spec.links) {
    const Eigen::Vector3d d = spec.points[l.a] - spec.points[l.b];
    constraints.push_back(
        {l.a, l.b, static_cast<float>(d.norm()), static_cast<float>(l.stiffness)});
  }
  c.colouring = motes::colour_constraints(constraints, static_cast<std::uint32_t>(p.size()));
  c.world.sizes.constraints = static_cast<std::uint32_t>(constraints.size());
  c.world.sizes.constraint_colours = static_cast<std::uint32_t>(c.colouring.colours());
  return c;
}

/// Constraints between random particles of a random world (any kind, pinned ones included).
inline LinkedCase random_links(std::uint32_t seed, std::size_t n, std::size_t links) {
  LinkedCase c;
  c.world = random_world(seed, n, 0u, kTestSkin);
  Rng rng(seed + 1u);
  std::vector<Constraint> constraints;
  for (std::size_t k = 0; k < links && n > 1; ++k) {
    const std::uint32_t a = rng.below(static_cast<std::uint32_t>(n));
    std::uint32_t b = rng.below(static_cast<std::uint32_t>(n));
    if (b == a) b = (a + 1) % static_cast<std::uint32_t>(n);
    constraints.push_back({a, b, rng.uniform(0.0f, 0.02f), rng.uniform(0.2f, 1.0f)});
  }
  c.colouring = motes::colour_constraints(constraints, static_cast<std::uint32_t>(n));
  c.world.sizes.constraints = static_cast<std::uint32_t>(constraints.size());
  c.world.sizes.constraint_colours = static_cast<std::uint32_t>(c.colouring.colours());
  return c;
}

inline motes::LinkedSpec rope(int count) {
  motes::RopeOptions o;
  o.from = Eigen::Vector3d(0.0, 0.5, 0.0);
  o.to = Eigen::Vector3d(0.01 * (count - 1), 0.5, 0.0);
  o.count = count;
  o.bend = true;
  motes::LinkedSpec r = motes::make_rope(o).value();
  r.pinned = {0u};
  return r;
}

inline motes::LinkedSpec cloth(int side) {
  motes::ClothOptions o;
  o.corner = Eigen::Vector3d(-0.1, 0.3, -0.1);
  o.edge_u = Eigen::Vector3d(0.01 * (side - 1), 0.0, 0.0);
  o.edge_v = Eigen::Vector3d(0.0, 0.0, 0.01 * (side - 1));
  o.nu = side;
  o.nv = side;
  o.bend_stiffness = 0.5;
  motes::LinkedSpec c = motes::make_cloth(o).value();
  c.pinned = {0u, static_cast<std::uint32_t>(side - 1)};
  return c;
}

/// The case of both families: `relax` runs every sweep in one constraints_relax call, else a
/// constraints_solve call per colour and sweep, as the core does; both are held to one oracle.
class ConstraintsCaseTest : public DeviceTest {
 protected:
  void run_case(bool relax, const std::string& layout, LinkedCase c, bool far,
                bool checked = true) {
    World& w = c.world;
    w.params.neighbour_skin = kConstraintsSkin;
    const std::vector<Constraint>& constraints = c.colouring.constraints;
    const std::vector<std::uint32_t>& first = c.colouring.first;
    auto colour_params = [&](int it, std::size_t k) {
      StepParams p = w.params;
      p.constraint_first = first[k];
      p.constraint_count = first[k + 1] - first[k];
      if (checked && it + 1 == kIterations) p.flags |= MOTES_FLAG_SKIN_CHECK;
      return p;
    };
    motes_ref::Particles want = w.particles;
    for (int it = 0; it < kIterations; ++it) {
      for (std::size_t k = 0; k < c.colouring.colours(); ++k) {
        motes_ref::constraints_solve(want, constraints, colour_params(it, k));
      }
    }
    Rng rng(static_cast<std::uint32_t>(w.sizes.particles) + 91u);
    std::vector<vec4> ref = moved_by(rng, want.pos, kConstraintsSkin, 0.3f);
    std::vector<bool> in_constraint(w.particles.size(), false);
    for (const Constraint& k : constraints) in_constraint[k.a] = in_constraint[k.b] = true;
    std::size_t moved_particle = w.particles.size();
    if (far && !constraints.empty()) {
      const Constraint& k = constraints[constraints.size() / 2];
      moved_particle = w.particles.vel[k.a].w != 0.0f ? k.a : k.b;
      ref[moved_particle] = moved_by(rng, {want.pos[moved_particle]}, kConstraintsSkin, 0.6f)[0];
    }
    motes_ref::Particles again = w.particles;
    bool rebuild = false;
    for (int it = 0; it < kIterations; ++it) {
      for (std::size_t k = 0; k < c.colouring.colours(); ++k) {
        rebuild =
            motes_ref::constraints_solve(again, constraints, colour_params(it, k), ref) || rebuild;
      }
    }
    ASSERT_EQ(rebuild, checked && moved_particle < w.particles.size() &&
                           w.particles.vel[moved_particle].w != 0.0f)
        << "the case's own premise";
    const std::vector<uint> state_in = {0u, 3u, 0u, 7u};

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    if (relax) {
      ASSERT_NO_FATAL_FAILURE(poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel,
                                              Buffer::Constraints, Buffer::ConstraintColours,
                                              Buffer::NeighbourRefPos, Buffer::NeighbourState}));
      if (!first.empty() && w.sizes.constraints > 0) {
        ASSERT_NO_FATAL_FAILURE(write(Buffer::ConstraintColours, first));
      }
    } else {
      ASSERT_NO_FATAL_FAILURE(
          poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::Constraints,
                          Buffer::NeighbourRefPos, Buffer::NeighbourState}));
    }
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Constraints, constraints));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    if (relax) {
      StepParams all = w.params;
      all.constraint_first = 0;
      all.constraint_count = static_cast<uint>(c.colouring.colours());
      all.constraint_sweeps = kIterations;
      if (checked) all.flags |= MOTES_FLAG_SKIN_CHECK;
      ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ConstraintsRelax, all));
    } else {
      for (int it = 0; it < kIterations; ++it) {
        for (std::size_t k = 0; k < c.colouring.colours(); ++k) {
          ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ConstraintsSolve, colour_params(it, k)));
        }
      }
    }
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));

    std::vector<uint> state_want = state_in;
    if (rebuild) state_want[MOTES_NEIGHBOUR_REBUILD] = 1u;
    std::vector<vec4> free_pos, free_pos_in, free_vel, free_vel_in;
    for (std::size_t i = 0; i < pos.size(); ++i) {
      if (in_constraint[i]) continue;
      free_pos.push_back(pos[i]);
      free_pos_in.push_back(w.particles.pos[i]);
      free_vel.push_back(vel[i]);
      free_vel_in.push_back(w.particles.vel[i]);
    }

    begin_case(std::string(relax ? "constraints_relax/" : "constraints_solve/") + layout + " (" +
                   std::to_string(c.colouring.colours()) + " colours)",
               static_cast<std::uint32_t>(constraints.size()));
    check_close("ParticlePos", pos, want.pos, kConstraintsSolveTolerance, Part::Xyz);
    const double ulp_per_dt = coordinate_ulp(want.pos) / static_cast<double>(w.params.gravity_dt.w);
    check_at_most("ParticleVel", "max dv (ulp/dt)", max_distance(vel, want.vel) / ulp_per_dt,
                  kConstraintsVelocityUlps);
    check_w_identical("ParticlePos.w (radius) kept", pos, w.particles.pos);
    check_w_identical("ParticleVel.w (inverse mass) kept", vel, w.particles.vel);
    check_identical("ParticlePos of particles in no constraint", free_pos, free_pos_in);
    check_identical("ParticleVel of particles in no constraint", free_vel, free_vel_in);
    check_identical("NeighbourState", state, state_want);
    end_case();
  }
};

/// The seven cases, as tests of fixture `Suite` (one whose run_case(layout, case, far, checked)
/// runs them its way).
#define MOTES_CONSTRAINTS_CASES(Suite)                                                             \
  TEST_P(Suite, Empty) { run_case("none", random_links(171, 31, 0), false); }                      \
  TEST_P(Suite, Rope31) { run_case("rope", from_linked(172, rope(31), 0.003f), true); }            \
  TEST_P(Suite, Cloth25) { run_case("cloth 25x25", from_linked(173, cloth(25), 0.003f), false); }  \
  TEST_P(Suite, Cloth25Moved) {                                                                    \
    run_case("cloth 25x25 moved_far", from_linked(173, cloth(25), 0.003f), true);                  \
  }                                                                                                \
  TEST_P(Suite, Cloth25MovedUnchecked) {                                                           \
    /* No launch asks for the skin test: the particle 0.6 skin off asks for nothing. */            \
    run_case("cloth 25x25 moved_far unchecked", from_linked(173, cloth(25), 0.003f), true, false); \
  }                                                                                                \
  TEST_P(Suite, Random1234) { run_case("random links", random_links(174, 1234, 3000), true); }     \
  TEST_P(Suite, Cloth256) {                                                                        \
    run_case("cloth 256x256", from_linked(175, cloth(256), 0.002f), false);                        \
  }

}  // namespace motes_conf

#endif  // MOTES_CONFORMANCE_CONSTRAINTS_CASES_H
