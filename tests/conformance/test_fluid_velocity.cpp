// fluid_velocity against the oracle (docs/fluids.md): ParticleVel of every particle (a fluid
// particle's velocity after XSPH, vorticity confinement, cohesion and adhesion, w kept; every
// other particle's untouched) and ParticleForce (untouched); with MOTES_FLAG_FLUID_ADHESION the
// solids' reactions to adhesion too (a rigid particle's momentum in ParticleForce with w = 0, a
// free solid particle's change of velocity; a static one's ParticleForce 0).
//
// The worlds of test_fluid_density.cpp (fluid_support.h: rigid bodies, some static, around a block
// of fluid), the fluid set in motion by fluid_stir (a rotation plus seeded noise) with every
// velocity-level parameter nonzero; FluidState the oracle's fluid_density and FluidVelOld,
// FluidAux, FluidNormal the oracle's fluid_vorticity of them; the fluid particles' ParticleVel xyz
// NaN (the kernel must read velocities from FluidVelOld only; w kept); ParticleForce a sentinel;
// every other buffer poisoned. Cases: sizes 0, 1, 31 and 1,234 (jittered lattice), the lattice at
// rest (cohesion and adhesion only), lists of capacity 4 against 64 (the over-capacity walk of the
// grid: the same sums); Block1234 first proves on the oracle that each of the four terms changes
// many particles' velocities; the solids' reactions with free solid particles in the block
// (fluid_free_solids), over full lists and over capacity. Physics: a uniform translation stays as
// it is under XSPH (device: fluid_vorticity then fluid_velocity).
//
// Tolerance: NMSE 1e-7 against the oracle on the fluid particles' change of velocity (the velocity
// minus FluidVelOld: about 1e-3 of it, which an NMSE of whole velocities would hide), on their
// velocities, on the free solids' change of velocity and on the rigid particles' reactions; w
// identical; every other particle's velocity and ParticleForce identical.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "fluid_support.h"

namespace motes_conf {
namespace {

constexpr double kFluidVelocityTolerance = 1.0e-7;

// The fluid particles' velocities minus FluidVelOld's (in float, as on the device's output).
std::vector<vec4> velocity_changes(const std::vector<vec4>& vel, const std::vector<vec4>& old,
                                   const StepParams& p) {
  std::vector<vec4> out;
  for (uint k = 0; k < p.fluid_count; ++k) {
    const vec4 v = vel[p.fluid_first + k];
    out.emplace_back(v.x - old[k].x, v.y - old[k].y, v.z - old[k].z, 0.0f);
  }
  return out;
}

// Elements [first, first + count) of v, and the rest.
std::vector<vec4> fluid_slice(const std::vector<vec4>& v, std::size_t first, std::size_t count) {
  return {v.begin() + std::ptrdiff_t(first), v.begin() + std::ptrdiff_t(first + count)};
}
std::vector<vec4> outside_fluid(const std::vector<vec4>& v, std::size_t first, std::size_t count) {
  std::vector<vec4> out(v.begin(), v.begin() + std::ptrdiff_t(first));
  out.insert(out.end(), v.begin() + std::ptrdiff_t(first + count), v.end());
  return out;
}

class FluidVelocity : public FluidTest {
 protected:
  // The oracle's inputs and result for fw (stirred) with lists of capacity K.
  struct Expected {
    std::vector<vec4> state;
    motes_ref::FluidVorticity vort;
    motes_ref::Particles written;  ///< the particles as written: fluid ParticleVel xyz NaN
    std::vector<vec4> vel;         ///< the oracle's ParticleVel
  };
  static Expected expected(const FluidWorld& fw, const StepParams& params) {
    Expected e;
    e.state =
        motes_ref::fluid_density(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, fw.state, params);
    e.vort = motes_ref::fluid_vorticity(fw.w.particles, fw.nb, fw.fluids, e.state, params);
    e.written = fw.w.particles;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (uint k = 0; k < params.fluid_count; ++k) {
      vec4& v = e.written.vel[params.fluid_first + k];
      v = vec4(nan, nan, nan, v.w);
    }
    e.vel = motes_ref::fluid_velocity(e.written, fw.nb, fw.fluids, e.state, e.vort, params);
    return e;
  }

  void run_case(const std::string& layout, FluidWorld fw, uint capacity, float spin, float noise,
                uint flags = 0u) {
    fluid_stir(fw, 7101, spin, noise, kFluidStirParameters);
    StepParams params = fw.w.params;
    params.neighbour_capacity = capacity;
    params.flags |= flags;
    const Expected want = expected(fw, params);
    // ParticleForce: a sentinel everywhere; only rigid particles' entries change, with the flag.
    const std::vector<vec4> sentinel(fw.w.particles.size(), vec4(7.0f, -7.0f, 7.0f, 7.0f));
    std::vector<vec4> want_force = sentinel;
    const std::vector<vec4> want_vel = motes_ref::fluid_velocity(
        want.written, fw.nb, fw.fluids, want.state, want.vort, params, &want_force);
    ASSERT_NO_FATAL_FAILURE(write_inputs(fw, capacity, want.state));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, want.written.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleForce, sentinel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::FluidVelOld, want.vort.vel_old));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::FluidAux, want.vort.aux));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::FluidNormal, want.vort.normal));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidVelocity, params));
    std::vector<vec4> got, force;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, got));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, force));
    const std::size_t nf = params.fluid_first, count = params.fluid_count;
    begin_case("fluid_velocity/" + layout, count);
    check_close("ParticleVel change", velocity_changes(got, want.vort.vel_old, params),
                velocity_changes(want_vel, want.vort.vel_old, params), kFluidVelocityTolerance,
                Part::Xyz);
    check_close("ParticleVel", fluid_slice(got, nf, count), fluid_slice(want_vel, nf, count),
                kFluidVelocityTolerance, Part::Xyz);
    check_w_identical("ParticleVel", got, want_vel);
    if ((flags & MOTES_FLAG_FLUID_ADHESION) == 0u) {
      check_identical("ParticleVel of the other particles", outside_fluid(got, nf, count),
                      outside_fluid(want_vel, nf, count));
      check_identical("ParticleForce", force, sentinel);
    } else {
      // The rigid particles' reactions; the free solids' change of velocity, each to the oracle.
      const std::size_t nr = params.rigid_particle_count;
      check_close("ParticleForce of the rigid particles", fluid_slice(force, 0, nr),
                  fluid_slice(want_force, 0, nr), kFluidVelocityTolerance, Part::Xyz);
      check_w_identical("ParticleForce", force, want_force);
      check_identical("ParticleForce of the other particles", outside_fluid(force, 0, nr),
                      outside_fluid(want_force, 0, nr));
      check_identical("ParticleVel of the rigid particles", fluid_slice(got, 0, nr),
                      fluid_slice(want_vel, 0, nr));
      std::vector<vec4> dv_got, dv_want;
      for (std::size_t b = nr; b < nf; ++b) {
        const vec4 v0 = want.written.vel[b];
        dv_got.emplace_back(got[b].x - v0.x, got[b].y - v0.y, got[b].z - v0.z, 0.0f);
        dv_want.emplace_back(want_vel[b].x - v0.x, want_vel[b].y - v0.y, want_vel[b].z - v0.z,
                             0.0f);
      }
      check_close("ParticleVel change of the free solids", dv_got, dv_want, kFluidVelocityTolerance,
                  Part::Xyz);
      check_identical("ParticleVel after the fluid",
                      fluid_slice(got, nf + count, got.size() - nf - count),
                      fluid_slice(want_vel, nf + count, want_vel.size() - nf - count));
    }
    end_case();
  }
};

TEST_P(FluidVelocity, Empty) { run_case("block", fluid_world(331, 0, 1.0f, 0.05f), 64, 3, 0.1f); }
TEST_P(FluidVelocity, One) { run_case("block", fluid_world(332, 4, 1.0f, 0.05f), 64, 3, 0.1f); }
TEST_P(FluidVelocity, Random31) {
  run_case("block", fluid_world(333, 104, 1.0f, 0.05f), 64, 3, 0.1f);
}
TEST_P(FluidVelocity, Block1234) {
  FluidWorld fw = fluid_world(334, 4114, 1.0f, 0.05f);
  {  // every term moves many velocities: each of c, eps, gamma, beta set to 0 on its own
    FluidWorld stirred = fw;
    fluid_stir(stirred, 7101, 3.0f, 0.1f, kFluidStirParameters);
    const StepParams& params = stirred.w.params;
    const std::vector<vec4> all = expected(stirred, params).vel;
    const char* names[] = {"XSPH", "vorticity confinement", "cohesion", "adhesion"};
    for (int t = 0; t < 4; ++t) {
      vec4 without = kFluidStirParameters;
      (t == 0 ? without.x : t == 1 ? without.y : t == 2 ? without.z : without.w) = 0.0f;
      FluidWorld one = fw;
      fluid_stir(one, 7101, 3.0f, 0.1f, without);
      const std::vector<vec4> less = expected(one, params).vel;
      std::size_t moved = 0;
      for (uint k = 0; k < params.fluid_count; ++k) {
        const vec4 a = all[params.fluid_first + k], b = less[params.fluid_first + k];
        moved += (a.x != b.x || a.y != b.y || a.z != b.z) ? 1u : 0u;
      }
      std::printf("[fluid_velocity] %s moves %zu of %u velocities\n", names[t], moved,
                  params.fluid_count);
      ASSERT_GE(moved, t == 3 ? 50u : params.fluid_count / 2) << names[t] << " is not exercised";
    }
  }
  run_case("block", fw, 64, 3, 0.1f);
}
TEST_P(FluidVelocity, LatticeAtRest) {
  run_case("lattice", fluid_world(335, 4114, 1.0f, 0.0f), 64, 0, 0);
}
TEST_P(FluidVelocity, OverCapacity) {
  run_case("capacity_4", fluid_world(338, 4114, 0.95f, 0.05f), 4, 3, 0.1f);
}

// With MOTES_FLAG_FLUID_ADHESION: every solid particle's reaction to adhesion. The world's rigid
// bodies (some static) and 300 free solid particles inside the stirred block; the oracle first
// shows that the reactions are there (many rigid particles and free solids take one; the free
// solids are the block's first 300 particles, whose far layers have no fluid within h).
TEST_P(FluidVelocity, SolidsTakeAdhesionsReaction) {
  FluidWorld fw = fluid_world(341, 4114, 1.0f, 0.05f);
  fluid_free_solids(fw, 300);
  {
    FluidWorld stirred = fw;
    fluid_stir(stirred, 7101, 3.0f, 0.1f, kFluidStirParameters);
    StepParams params = stirred.w.params;
    params.flags |= MOTES_FLAG_FLUID_ADHESION;
    const Expected e = expected(stirred, params);
    std::vector<vec4> force(stirred.w.particles.size(), vec4(0.0f));
    const std::vector<vec4> vel = motes_ref::fluid_velocity(e.written, stirred.nb, stirred.fluids,
                                                            e.state, e.vort, params, &force);
    std::size_t rigid = 0, free = 0;
    for (uint b = 0; b < params.rigid_particle_count; ++b) {
      rigid += (force[b].x != 0.0f || force[b].y != 0.0f || force[b].z != 0.0f) ? 1u : 0u;
    }
    for (uint b = params.rigid_particle_count; b < params.fluid_first; ++b) {
      const vec4 a = vel[b], o = e.written.vel[b];
      free += (a.x != o.x || a.y != o.y || a.z != o.z) ? 1u : 0u;
    }
    std::printf("[fluid_velocity] adhesion's reaction on %zu rigid particles and %zu of 300 free\n",
                rigid, free);
    ASSERT_GE(rigid, 20u);
    ASSERT_GE(free, 150u);  // the slab's far layers have no fluid within h
  }
  run_case("adhesion_reaction", fw, 64, 3, 0.1f, MOTES_FLAG_FLUID_ADHESION);
}
TEST_P(FluidVelocity, SolidsTakeAdhesionsReactionOverCapacity) {
  FluidWorld fw = fluid_world(342, 4114, 0.95f, 0.05f);
  fluid_free_solids(fw, 300);
  run_case("adhesion_reaction_capacity_4", fw, 4, 3, 0.1f, MOTES_FLAG_FLUID_ADHESION);
}

// A uniform translation of a jittered block under XSPH (c = 0.1, the other terms 0), on the
// device from the start (fluid_vorticity, then fluid_velocity): every difference v_j - v_i is 0,
// so every velocity stays as it was, to float rounding.
TEST_P(FluidVelocity, UniformTranslationUnderXsph) {
  FluidWorld fw = fluid_world(339, 4114, 1.0f, 0.05f);
  fluid_stir(fw, 7102, 0.0f, 0.0f, vec4(0.1f, 0.0f, 0.0f, 0.0f));
  StepParams params = fw.w.params;
  const vec3 u(0.3f, -0.2f, 0.1f);
  for (uint k = 0; k < params.fluid_count; ++k) {
    vec4& v = fw.w.particles.vel[params.fluid_first + k];
    v = vec4(u.x, u.y, u.z, v.w);
  }
  const std::vector<vec4> state =
      motes_ref::fluid_density(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, fw.state, params);
  ASSERT_NO_FATAL_FAILURE(write_inputs(fw, 64, state));
  ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidVorticity, params));
  ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidVelocity, params));
  std::vector<vec4> got;
  ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, got));
  begin_case("fluid_velocity/uniform_translation", params.fluid_count);
  double worst = 0.0;
  for (uint k = 0; k < params.fluid_count; ++k) {
    const vec4 v = got[params.fluid_first + k];
    worst = std::max({worst, std::abs(double(v.x) - double(u.x)),
                      std::abs(double(v.y) - double(u.y)), std::abs(double(v.z) - double(u.z))});
  }
  check_at_most("|v - u| of every fluid particle", "max |v - u| (m/s)", worst, 1e-7);
  check_w_identical("ParticleVel", got, fw.w.particles.vel);
  check_identical("ParticleVel of the other particles",
                  outside_fluid(got, params.fluid_first, params.fluid_count),
                  outside_fluid(fw.w.particles.vel, params.fluid_first, params.fluid_count));
  end_case();
}

INSTANTIATE_TEST_SUITE_P(Conformance, FluidVelocity, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
