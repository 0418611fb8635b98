// fluid_update against the oracle (docs/fluids.md): ParticleForce of every particle (a fluid
// particle's correction dx_i with w = 1; a solid particle's reaction to the liquid: a rigid
// particle's momentum with w = 0, a free solid particle's shift with w = 1; a static one's 0).
//
// The worlds of test_fluid_density.cpp (fluid_support.h), with FluidState the oracle's
// fluid_density of them (the lambdas a sweep gives); every other buffer poisoned. Cases: sizes 0,
// 1, 31 and 1,234, the lattice at rest, a compressed block, free solid particles inside the block
// (fluid_free_solids), lists of capacity 4 against 64.
//
// Tolerance: NMSE 1e-7 against the oracle on xyz (the shifts, about 1e-6 m: compared with w in
// the norm they would hide), w identical (1 for a fluid particle, 0 for the others).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fluid_support.h"

namespace motes_conf {
namespace {

constexpr double kFluidUpdateTolerance = 1.0e-7;

class FluidUpdate : public FluidTest {
 protected:
  void run_case(const std::string& layout, const FluidWorld& fw, uint capacity) {
    StepParams params = fw.w.params;
    params.neighbour_capacity = capacity;
    const std::vector<vec4> state =
        motes_ref::fluid_density(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, fw.state, params);
    const std::vector<vec4> want =
        motes_ref::fluid_update(fw.w.particles, fw.nb, fw.w.planes, fw.fluids, state, params);
    ASSERT_NO_FATAL_FAILURE(write_inputs(fw, capacity, state));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::FluidUpdate, params));
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, got));
    begin_case("fluid_update/" + layout, fw.w.particles.size());
    check_close("ParticleForce", got, want, kFluidUpdateTolerance, Part::Xyz);
    check_w_identical("ParticleForce", got, want);
    end_case();
  }
};

TEST_P(FluidUpdate, Empty) { run_case("block", fluid_world(311, 0, 1.0f, 0.05f), 64); }
TEST_P(FluidUpdate, One) { run_case("block", fluid_world(312, 4, 1.0f, 0.05f), 64); }
TEST_P(FluidUpdate, Random31) { run_case("block", fluid_world(313, 104, 1.0f, 0.05f), 64); }
TEST_P(FluidUpdate, Block1234) { run_case("block", fluid_world(314, 4114, 1.0f, 0.05f), 64); }
TEST_P(FluidUpdate, LatticeAtRest) { run_case("lattice", fluid_world(315, 4114, 1.0f, 0.0f), 64); }
TEST_P(FluidUpdate, Compressed) { run_case("compressed", fluid_world(316, 4114, 0.9f, 0.05f), 64); }
TEST_P(FluidUpdate, FreeSolidsReact) {
  FluidWorld fw = fluid_world(319, 4114, 0.95f, 0.05f);
  fluid_free_solids(fw, 300);
  run_case("free_solids", fw, 64);
}
TEST_P(FluidUpdate, OverCapacity) {
  run_case("capacity_4", fluid_world(318, 4114, 0.95f, 0.05f), 4);
}

INSTANTIATE_TEST_SUITE_P(Conformance, FluidUpdate, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
