// fluid_density against the oracle (docs/fluids.md): FluidState of every fluid particle.
//
// A world of rigid bodies (some static) around a block of fluid particles with two planes near it
// (fluid_support.h); the oracle's lists (with the fluid's reach h), grid and a random earlier
// FluidState are written, every other buffer is poisoned. Read back: FluidState (rho, lambda,
// Lambda, 0). Cases: sizes 0, 1, 31 and 1,234 (jittered lattice), the lattice at rest (spacing d:
// 1% over rest, so every lambda but the surface's is negative), a compressed block (0.9 d), the
// substep's first sweep (MOTES_FLAG_POSITION_FIRST: Lambda = lambda) and lists of capacity 4
// against 64 (the over-capacity walk of the grid: the same sums).
//
// Tolerance: NMSE 1e-7 against the oracle for rho, lambda and Lambda each (float sums in one order
// on every backend; fused multiply-adds and the compilers' rounding differ).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fluid_support.h"

namespace motes_conf {
namespace {

constexpr double kFluidDensityTolerance = 1.0e-7;

class FluidDensity : public FluidTest {
 protected:
  void run_case(const std::string& layout, const FluidWorld& fw, bool first, uint capacity) {
    StepParams params = fw.w.params;
    params.neighbour_capacity = capacity;
    if (first) params.flags |= MOTES_FLAG_POSITION_FIRST;
    const std::vector<vec4> want =
        motes_ref::fluid_density(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, fw.state, params);
    if (fw.state.size() >= 31) {
      std::size_t pressed = 0;
      for (const vec4& s : want) pressed += s.y < 0.0f ? 1u : 0u;
      ASSERT_GE(pressed, want.size() / 4) << "too few compressed particles to prove much";
    }
    ASSERT_NO_FATAL_FAILURE(write_inputs(fw, capacity, fw.state));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidDensity, params));
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::FluidState, got));
    begin_case("fluid_density/" + layout, fw.state.size());
    check_close("FluidState rho", component(got, 0), component(want, 0), kFluidDensityTolerance);
    check_close("FluidState lambda", component(got, 1), component(want, 1), kFluidDensityTolerance);
    check_close("FluidState Lambda", component(got, 2), component(want, 2), kFluidDensityTolerance);
    check_identical("FluidState w", component(got, 3), component(want, 3));
    end_case();
  }
};

TEST_P(FluidDensity, Empty) { run_case("block", fluid_world(301, 0, 1.0f, 0.05f), false, 64); }
TEST_P(FluidDensity, One) { run_case("block", fluid_world(302, 4, 1.0f, 0.05f), false, 64); }
TEST_P(FluidDensity, Random31) { run_case("block", fluid_world(303, 104, 1.0f, 0.05f), false, 64); }
TEST_P(FluidDensity, Block1234) {
  run_case("block", fluid_world(304, 4114, 1.0f, 0.05f), false, 64);
}
TEST_P(FluidDensity, LatticeAtRest) {
  run_case("lattice", fluid_world(305, 4114, 1.0f, 0.0f), false, 64);
}
TEST_P(FluidDensity, Compressed) {
  run_case("compressed", fluid_world(306, 4114, 0.9f, 0.05f), false, 64);
}
TEST_P(FluidDensity, FirstSweep) {
  run_case("first_sweep", fluid_world(307, 4114, 0.95f, 0.05f), true, 64);
}
TEST_P(FluidDensity, OverCapacity) {
  const FluidWorld fw = fluid_world(308, 4114, 0.95f, 0.05f);
  run_case("capacity_4", fw, false, 4);
}

INSTANTIATE_TEST_SUITE_P(Conformance, FluidDensity, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
