// fluid_vorticity against the oracle (docs/fluids.md): FluidVelOld, FluidAux and FluidNormal of
// every fluid particle.
//
// The worlds of test_fluid_density.cpp (fluid_support.h: rigid bodies, some static, around a block
// of fluid), the fluid set in motion by fluid_stir (a rotation plus seeded noise), FluidState the
// oracle's fluid_density of them (the densities a sweep leaves); every other buffer poisoned, the
// outputs included. Read back: FluidVelOld (v_i, 0), FluidAux (omega_i, |omega_i|), FluidNormal
// (n_i, 0). Cases: sizes 0, 1, 31 and 1,234 (jittered lattice), the lattice at rest (omega 0,
// normals only at the surface), lists of capacity 4 against 64 (the over-capacity walk of the
// grid: the same sums), and the physics of a rigid rotation: in the bulk of the lattice omega
// reads the SPH curl of 2 Omega (FluidMath.VorticityOfARigidRotation: 5.68 for 6) and n_i
// vanishes.
//
// Tolerance: NMSE 1e-7 against the oracle for omega, |omega| and n each (float sums in one order
// on every backend; fused multiply-adds and the compilers' rounding differ); FluidVelOld is a
// copy (identical) and the w of FluidNormal is 0 (identical).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fluid_support.h"

namespace motes_conf {
namespace {

constexpr double kFluidVorticityTolerance = 1.0e-7;

class FluidVorticity : public FluidTest {
 protected:
  void run_case(const std::string& layout, FluidWorld fw, uint capacity, float spin, float noise) {
    fluid_stir(fw, 7001, spin, noise, kFluidStirParameters);
    StepParams params = fw.w.params;
    params.neighbour_capacity = capacity;
    const std::vector<vec4> state =
        motes_ref::fluid_density(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, fw.state, params);
    const motes_ref::FluidVorticity want =
        motes_ref::fluid_vorticity(fw.w.particles, fw.nb, fw.fluids, state, params);
    ASSERT_NO_FATAL_FAILURE(write_inputs(fw, capacity, state));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidVorticity, params));
    std::vector<vec4> vel_old, aux, normal;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidVelOld, vel_old));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidAux, aux));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidNormal, normal));
    begin_case("fluid_vorticity/" + layout, state.size());
    check_identical("FluidVelOld", vel_old, want.vel_old);
    check_close("FluidAux omega", aux, want.aux, kFluidVorticityTolerance, Part::Xyz);
    check_close("FluidAux |omega|", component(aux, 3), component(want.aux, 3),
                kFluidVorticityTolerance);
    check_close("FluidNormal", normal, want.normal, kFluidVorticityTolerance, Part::Xyz);
    check_w_identical("FluidNormal", normal, want.normal);
    end_case();
  }
};

TEST_P(FluidVorticity, Empty) { run_case("block", fluid_world(321, 0, 1.0f, 0.05f), 64, 3, 0.1f); }
TEST_P(FluidVorticity, One) { run_case("block", fluid_world(322, 4, 1.0f, 0.05f), 64, 3, 0.1f); }
TEST_P(FluidVorticity, Random31) {
  run_case("block", fluid_world(323, 104, 1.0f, 0.05f), 64, 3, 0.1f);
}
TEST_P(FluidVorticity, Block1234) {
  run_case("block", fluid_world(324, 4114, 1.0f, 0.05f), 64, 3, 0.1f);
}
TEST_P(FluidVorticity, LatticeAtRest) {
  run_case("lattice", fluid_world(325, 4114, 1.0f, 0.0f), 64, 0, 0);
}
TEST_P(FluidVorticity, OverCapacity) {
  run_case("capacity_4", fluid_world(328, 4114, 0.95f, 0.05f), 4, 3, 0.1f);
}

// A rigid rotation Omega = 3 rad/s about y of the lattice (every density the lattice's own, so
// that only the kernel's sums are measured): in the bulk (the first three shells full) omega is
// the SPH curl of the rotation, 2 Omega times the lattice's moment of the spiky gradient (5.68 for
// 6, as FluidMath.VorticityOfARigidRotation), and the normal n_i vanishes.
TEST_P(FluidVorticity, RigidRotation) {
  FluidWorld fw = fluid_world(329, 4114, 1.0f, 0.0f);
  fluid_stir(fw, 7002, 3.0f, 0.0f, kFluidStirParameters);
  const StepParams& params = fw.w.params;
  const motes::shared::FluidMaterial f = fw.fluids[kFluidMaterial];
  const float h = f.density_h.y;
  double rho = 0.0;  // the density of a lattice particle at rest
  for (int x = -2; x <= 2; ++x)
    for (int y = -2; y <= 2; ++y)
      for (int z = -2; z <= 2; ++z) {
        const float r2 = float(x * x + y * y + z * z) * kFluidDiameter * kFluidDiameter;
        rho += double(f.density_h.z) * double(motes::shared::fluid_poly6(r2, h));
      }
  const std::vector<vec4> state(params.fluid_count, vec4(float(rho), 0.0f, 0.0f, 0.0f));
  ASSERT_NO_FATAL_FAILURE(write_inputs(fw, 64, state));
  ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidVorticity, params));
  std::vector<vec4> aux, normal;
  ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidAux, aux));
  ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidNormal, normal));
  begin_case("fluid_vorticity/rigid_rotation", state.size());
  std::size_t bulk = 0;
  double worst_curl = 0.0, worst_across = 0.0, worst_normal = 0.0;
  for (uint k = 0; k < params.fluid_count; ++k) {
    const uint i = params.fluid_first + k;
    // The bulk: the lattice's first three shells (26 fluid neighbours closer than 1.9 d) all
    // there; the fourth, at 2 d = h, adds nothing (solids count in neither sum).
    std::size_t shells = 0;
    for (const uint j : fw.nb.lists[i]) {
      const vec3 r =
          motes::shared::xyz(fw.w.particles.pos[i]) - motes::shared::xyz(fw.w.particles.pos[j]);
      const bool fluid_j = j - params.fluid_first < params.fluid_count;
      if (fluid_j && motes::shared::dot(r, r) < 3.61f * kFluidDiameter * kFluidDiameter) ++shells;
    }
    if (shells != 26) continue;
    ++bulk;
    worst_curl = std::max(worst_curl, std::abs(double(aux[k].y) - 5.68));
    worst_across = std::max({worst_across, std::abs(double(aux[k].x)), std::abs(double(aux[k].z))});
    worst_normal =
        std::max(worst_normal, std::sqrt(double(motes::shared::dot(
                                   motes::shared::xyz(normal[k]), motes::shared::xyz(normal[k])))));
  }
  check_that("a bulk of at least 200 particles", bulk >= 200);
  check_at_most("omega_y in the bulk against 5.68 (2 Omega = 6)", "max |omega_y - 5.68| (1/s)",
                worst_curl, 0.01);
  check_at_most("omega_x, omega_z in the bulk", "max |omega_xz| (1/s)", worst_across, 1e-3);
  check_at_most("|n| in the bulk", "max |n|", worst_normal, 1e-4);
  end_case();
}

INSTANTIATE_TEST_SUITE_P(Conformance, FluidVorticity, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
